// Recording files: writing (zlib-packed chunks) and reading back with every check a damaged or
// foreign file needs (magic, version, sizes, CRC), so a bad file is an error message, not a crash.
#include "io/recording.h"

#include <zlib.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <nlohmann/json.hpp>

namespace rm3d {

namespace {

constexpr char kMagic[8] = {'R', 'M', '3', 'D', 'R', 'E', 'C', '\n'};
constexpr uint32_t tag(const char (&s)[5]) {
  return uint32_t(uint8_t(s[0])) | uint32_t(uint8_t(s[1])) << 8 | uint32_t(uint8_t(s[2])) << 16 |
         uint32_t(uint8_t(s[3])) << 24;
}
constexpr uint32_t kMeta = tag("META"), kLayout = tag("LAYO"), kFrame = tag("FRAM"), kSources = tag("SRCS"),
                   kEnd = tag("END_");
constexpr uint64_t kMaxChunk = uint64_t(1) << 32;  // 4 GiB unpacked: more is a damaged size field
constexpr uint64_t kMaxRatio = 1032;  // zlib's best: no chunk unpacks to more than 1032x its packed size

std::string tagName(uint32_t t) {
  std::string s;
  for (int i = 0; i < 4; ++i) {
    const char c = char((t >> (8 * i)) & 0xff);
    s += c >= 32 && c < 127 ? c : '?';
  }
  return s;
}

/// Appends plain values (the host is little-endian: x86-64 and arm64 both are).
struct Out {
  std::vector<uint8_t>& b;
  template <class T>
  void put(const T& v) {
    const auto* p = reinterpret_cast<const uint8_t*>(&v);
    b.insert(b.end(), p, p + sizeof(T));
  }
  void str(const std::string& s) {
    put(uint32_t(s.size()));
    b.insert(b.end(), s.begin(), s.end());
  }
  void pose(const Pose& p) {
    for (int i = 0; i < 3; ++i) put(p.pos[i]);
    put(p.rot.w());
    put(p.rot.x());
    put(p.rot.y());
    put(p.rot.z());
  }
};

/// Reads them back; any overrun sets `bad` and yields zeros (the caller reports it once).
struct In {
  const uint8_t* p;
  size_t n, at = 0;
  bool bad = false;
  template <class T>
  T get() {
    T v{};
    if (at + sizeof(T) > n) {
      bad = true;
      at = n;
      return v;
    }
    std::memcpy(&v, p + at, sizeof(T));
    at += sizeof(T);
    return v;
  }
  std::string str() {
    const uint32_t len = get<uint32_t>();
    if (bad || at + len > n) {
      bad = true;
      return {};
    }
    std::string s(reinterpret_cast<const char*>(p + at), len);
    at += len;
    return s;
  }
  Pose pose() {
    Pose q;
    for (int i = 0; i < 3; ++i) q.pos[i] = get<double>();
    const double w = get<double>(), x = get<double>(), y = get<double>(), z = get<double>();
    q.rot = Quat(w, x, y, z);
    return q;
  }
  /// A count of items of at least `minBytes` each that fit in what is left.
  uint32_t count(size_t minBytes) {
    const uint32_t c = get<uint32_t>();
    if (size_t(c) * std::max<size_t>(minBytes, 1) > n - at) bad = true;
    return bad ? 0 : c;
  }
};

/// Byte planes: byte k of every 8-byte lane together. The XOR of two close doubles is zero in its
/// high bytes, so the planes of high bytes pack to almost nothing (the tail past the last whole
/// lane stays in place).
void shuffle(const uint8_t* in, uint8_t* out, size_t n) {
  const size_t lanes = n / 8;
  for (size_t i = 0; i < lanes; ++i)
    for (size_t k = 0; k < 8; ++k) out[k * lanes + i] = in[i * 8 + k];
  for (size_t i = lanes * 8; i < n; ++i) out[i] = in[i];
}
void unshuffle(const uint8_t* in, uint8_t* out, size_t n) {
  const size_t lanes = n / 8;
  for (size_t i = 0; i < lanes; ++i)
    for (size_t k = 0; k < 8; ++k) out[i * 8 + k] = in[k * lanes + i];
  for (size_t i = lanes * 8; i < n; ++i) out[i] = in[i];
}

size_t clothNodes(const SceneLayout& l) {
  size_t n = 0;
  for (const SceneLayout::Cloth& c : l.cloths) n += size_t(c.nodes);
  return n;
}

size_t particleCount(const SceneLayout& l) {
  size_t n = 0;
  for (const SceneLayout::Particles& p : l.particles) n += size_t(p.count);
  return n;
}

size_t stateBytes(const SceneLayout& l) {
  return size_t(l.linkCount) * 56 + size_t(l.jointCount) * 8 + size_t(l.dockCount) + l.modules.size() +
         l.ranges.size() * 8 + l.bodyRadius.size() * 56 + clothNodes(l) * 12 + particleCount(l) * 12;
}

void putState(Out& o, const SceneState& s) {
  for (const Pose& p : s.links) o.pose(p);
  for (double j : s.joints) o.put(j);
  o.b.insert(o.b.end(), s.docks.begin(), s.docks.end());
  o.b.insert(o.b.end(), s.faulted.begin(), s.faulted.end());
  for (double r : s.rangeHits) o.put(r);
  for (const Pose& p : s.bodies) o.pose(p);
  for (const Eigen::Vector3f& v : s.clothNodes) o.put(v.x()), o.put(v.y()), o.put(v.z());
  for (const Eigen::Vector3f& v : s.particles) o.put(v.x()), o.put(v.y()), o.put(v.z());
}

void getState(In& in, const SceneLayout& l, SceneState& s) {
  s.links.resize(size_t(l.linkCount));
  s.joints.resize(size_t(l.jointCount));
  s.docks.resize(size_t(l.dockCount));
  s.faulted.resize(l.modules.size());
  s.rangeHits.resize(l.ranges.size());
  s.bodies.resize(l.bodyRadius.size());
  for (Pose& p : s.links) p = in.pose();
  for (double& j : s.joints) j = in.get<double>();
  for (uint8_t& d : s.docks) d = in.get<uint8_t>();
  for (uint8_t& f : s.faulted) f = in.get<uint8_t>();
  for (double& r : s.rangeHits) r = in.get<double>();
  for (Pose& p : s.bodies) p = in.pose();
  s.clothNodes.resize(clothNodes(l));
  for (Eigen::Vector3f& v : s.clothNodes)
    for (int i = 0; i < 3; ++i) v[i] = in.get<float>();
  s.particles.resize(particleCount(l));
  for (Eigen::Vector3f& v : s.particles)
    for (int i = 0; i < 3; ++i) v[i] = in.get<float>();
}

void putLayout(Out& o, const SceneLayout& l) {
  o.put(uint32_t(l.meshes.size()));
  for (const RenderMesh& m : l.meshes) {
    o.put(uint32_t(m.vertices.size()));
    for (const Eigen::Vector3f& v : m.vertices)
      for (int i = 0; i < 3; ++i) o.put(v[i]);
    o.put(uint32_t(m.indices.size()));
    for (uint32_t i : m.indices) o.put(i);
  }
  o.put(uint32_t(l.items.size()));
  for (const SceneLayout::Item& it : l.items) {
    o.put(uint8_t(it.kind));
    o.put(int32_t(it.owner));
    o.put(int32_t(it.link));
    o.put(int32_t(it.dock));
    o.pose(it.local);
    for (int i = 0; i < 3; ++i) o.put(it.scale[i]);
    for (float c : it.color) o.put(c);
    o.put(int32_t(it.mesh));
  }
  o.put(uint32_t(l.ranges.size()));
  for (const SceneLayout::Range& r : l.ranges) {
    o.put(int32_t(r.module));
    o.put(int32_t(r.link));
    for (int i = 0; i < 3; ++i) o.put(r.pos[i]);
    for (int i = 0; i < 3; ++i) o.put(r.dir[i]);
    o.put(r.minRange);
    o.put(r.maxRange);
  }
  o.put(uint32_t(l.modules.size()));
  for (const SceneLayout::ModuleInfo& m : l.modules) {
    o.str(m.name);
    o.str(m.type);
    o.put(int32_t(m.id));
    o.put(int32_t(m.rootLink));
    o.put(int32_t(m.links));
    o.put(uint32_t(m.joints.size()));
    for (const std::string& j : m.joints) o.str(j);
    o.put(uint32_t(m.docks.size()));
    for (const std::string& d : m.docks) o.str(d);
  }
  o.put(uint32_t(l.bodyRadius.size()));
  for (double r : l.bodyRadius) o.put(r);
  o.put(uint8_t(l.ground));
  o.put(l.dt);
  const SceneLayout::CameraDef& c = l.camera;
  o.put(uint8_t((c.eye ? 1 : 0) | (c.target ? 2 : 0)));
  const Vec3 eye = c.eye.value_or(Vec3::Zero()), target = c.target.value_or(Vec3::Zero());
  for (int i = 0; i < 3; ++i) o.put(eye[i]);
  for (int i = 0; i < 3; ++i) o.put(target[i]);
  o.put(int32_t(c.follow));
  o.put(c.fovDeg);
  // Cloth, after everything a layout without it has (files from before cloth simply end here).
  o.put(uint32_t(l.cloths.size()));
  for (const SceneLayout::Cloth& cl : l.cloths) {
    o.put(int32_t(cl.nodes));
    o.put(uint32_t(cl.triangles.size()));
    for (uint32_t t : cl.triangles) o.put(t);
    for (float f : cl.color) o.put(f);
  }
  // Added later, at the end so older readers stop before it: each mesh's grid (terrain).
  for (const RenderMesh& m : l.meshes) {
    o.put(m.grid.x());
    o.put(m.grid.y());
  }
  // Then the particle systems (count, radius, colour).
  o.put(uint32_t(l.particles.size()));
  for (const SceneLayout::Particles& p : l.particles) {
    o.put(int32_t(p.count));
    o.put(p.radius);
    for (float f : p.color) o.put(f);
  }
}

/// Reads a layout and checks every index in it, so drawing from it cannot go out of bounds.
bool getLayout(In& in, SceneLayout& l, std::string& why) {
  l.meshes.resize(in.count(8));
  for (RenderMesh& m : l.meshes) {
    m.vertices.resize(in.count(12));
    for (Eigen::Vector3f& v : m.vertices)
      for (int i = 0; i < 3; ++i) v[i] = in.get<float>();
    m.indices.resize(in.count(4));
    for (uint32_t& i : m.indices) i = in.get<uint32_t>();
    for (uint32_t i : m.indices)
      if (i >= m.vertices.size()) return why = "a mesh index past its vertices", false;
  }
  l.items.resize(in.count(1));
  for (SceneLayout::Item& it : l.items) {
    it.kind = SceneLayout::Kind(in.get<uint8_t>());
    it.owner = in.get<int32_t>();
    it.link = in.get<int32_t>();
    it.dock = in.get<int32_t>();
    it.local = in.pose();
    for (int i = 0; i < 3; ++i) it.scale[i] = in.get<float>();
    for (float& c : it.color) c = in.get<float>();
    it.mesh = in.get<int32_t>();
  }
  l.ranges.resize(in.count(8));
  for (SceneLayout::Range& r : l.ranges) {
    r.module = in.get<int32_t>();
    r.link = in.get<int32_t>();
    for (int i = 0; i < 3; ++i) r.pos[i] = in.get<double>();
    for (int i = 0; i < 3; ++i) r.dir[i] = in.get<double>();
    r.minRange = in.get<double>();
    r.maxRange = in.get<double>();
  }
  l.modules.resize(in.count(8));
  l.linkCount = l.jointCount = l.dockCount = 0;
  for (SceneLayout::ModuleInfo& m : l.modules) {
    m.name = in.str();
    m.type = in.str();
    m.id = in.get<int32_t>();
    m.rootLink = in.get<int32_t>();
    m.links = in.get<int32_t>();
    m.joints.resize(in.count(4));
    for (std::string& j : m.joints) j = in.str();
    m.docks.resize(in.count(4));
    for (std::string& d : m.docks) d = in.str();
    if (m.links < 1 || m.links > 1 << 16 || m.rootLink < 0 || m.rootLink >= m.links)
      return why = "a module with bad link counts", false;
    m.firstLink = l.linkCount;
    m.firstJoint = l.jointCount;
    m.firstDock = l.dockCount;
    l.linkCount += m.links;
    l.jointCount += int(m.joints.size());
    l.dockCount += int(m.docks.size());
  }
  l.bodyRadius.resize(in.count(8));
  for (double& r : l.bodyRadius) r = in.get<double>();
  l.ground = in.get<uint8_t>() != 0;
  l.dt = in.get<double>();
  const uint8_t has = in.get<uint8_t>();
  Vec3 eye, target;
  for (int i = 0; i < 3; ++i) eye[i] = in.get<double>();
  for (int i = 0; i < 3; ++i) target[i] = in.get<double>();
  if (has & 1) l.camera.eye = eye;
  if (has & 2) l.camera.target = target;
  l.camera.follow = in.get<int32_t>();
  l.camera.fovDeg = in.get<double>();
  l.cloths.resize(in.at < in.n ? in.count(8) : 0);
  for (SceneLayout::Cloth& cl : l.cloths) {
    cl.nodes = in.get<int32_t>();
    cl.triangles.resize(in.count(4));
    for (uint32_t& t : cl.triangles) t = in.get<uint32_t>();
    for (float& f : cl.color) f = in.get<float>();
    if (cl.nodes < 0 || cl.nodes > (1 << 24)) return why = "a cloth with a bad node count", false;
    for (uint32_t t : cl.triangles)
      if (t >= uint32_t(cl.nodes)) return why = "a cloth triangle past its nodes", false;
  }
  if (in.bad) return why = "it ends early", false;
  if (in.n - in.at >= l.meshes.size() * 8)  // mesh grids (absent in older recordings)
    for (RenderMesh& m : l.meshes) {
      m.grid.x() = in.get<float>();
      m.grid.y() = in.get<float>();
      if (!(m.grid.x() >= 0 && m.grid.y() >= 0 && m.grid.x() < 1e7f && m.grid.y() < 1e7f))
        return why = "a bad mesh grid", false;
    }
  l.particles.resize(in.at < in.n ? in.count(24) : 0);
  for (SceneLayout::Particles& p : l.particles) {
    p.count = in.get<int32_t>();
    p.radius = in.get<float>();
    for (float& f : p.color) f = in.get<float>();
    if (p.count < 0 || p.count > (1 << 24)) return why = "a particle system with a bad count", false;
    if (!(p.radius > 0 && p.radius < 10)) return why = "a particle system with a bad radius", false;
  }
  if (in.bad) return why = "it ends early", false;
  if (!(l.dt > 0 && l.dt <= 1)) return why = "a bad dt", false;
  const int modules = int(l.modules.size()), bodies = int(l.bodyRadius.size());
  for (const SceneLayout::Item& it : l.items) {
    if (it.mesh < 0 || it.mesh >= int(l.meshes.size())) return why = "an item with a bad mesh index", false;
    if (it.kind == SceneLayout::Kind::Body) {
      if (it.owner < 0 || it.owner >= bodies) return why = "an item on a body that is not there", false;
      continue;
    }
    if (it.kind != SceneLayout::Kind::Link && it.kind != SceneLayout::Kind::Dock)
      return why = "an item of an unknown kind", false;
    if (it.owner < 0 || it.owner >= modules) return why = "an item on a module that is not there", false;
    const SceneLayout::ModuleInfo& m = l.modules[size_t(it.owner)];
    if (it.link < 0 || it.link >= m.links) return why = "an item on a link that is not there", false;
    if (it.kind == SceneLayout::Kind::Dock && (it.dock < 0 || it.dock >= int(m.docks.size())))
      return why = "an item on a dock that is not there", false;
  }
  for (const SceneLayout::Range& r : l.ranges)
    if (r.module < 0 || r.module >= modules || r.link < 0 || r.link >= l.modules[size_t(r.module)].links)
      return why = "a range sensor on a link that is not there", false;
  if (l.camera.follow >= modules) l.camera.follow = -1;
  return true;
}

}  // namespace

// --- writing ---

RecordingWriter::~RecordingWriter() {
  if (m_file) std::fclose(m_file);
}

void RecordingWriter::chunk(uint32_t t, const std::vector<uint8_t>& raw) {
  if (!m_file || m_failed) return;
  uLongf packed = compressBound(uLong(raw.size()));
  m_packed.resize(packed);
  if (compress2(m_packed.data(), &packed, raw.data(), uLong(raw.size()), 1) != Z_OK) {
    m_failed = true;
    return;
  }
  const uint32_t crc = uint32_t(crc32(0, raw.data(), uInt(raw.size())));
  const uint64_t rawSize = raw.size(), packedSize = packed;
  bool ok = std::fwrite(&t, 4, 1, m_file) == 1 && std::fwrite(&crc, 4, 1, m_file) == 1 &&
            std::fwrite(&rawSize, 8, 1, m_file) == 1 && std::fwrite(&packedSize, 8, 1, m_file) == 1 &&
            std::fwrite(m_packed.data(), 1, packed, m_file) == packed;
  if (!ok) m_failed = true;
  m_bytes += 24 + packed;
}

bool RecordingWriter::open(const std::string& path, const RecordingMeta& meta, const SceneLayout& layout,
                           std::string& err) {
  m_path = path;
  m_file = std::fopen(path.c_str(), "wb");
  if (!m_file) {
    err = "--record " + path + ": cannot create the file (" + std::strerror(errno) + ")";
    return false;
  }
  const uint32_t version = kRecordingVersion, reserved = 0;
  if (std::fwrite(kMagic, 8, 1, m_file) != 1 || std::fwrite(&version, 4, 1, m_file) != 1 ||
      std::fwrite(&reserved, 4, 1, m_file) != 1)
    m_failed = true;
  m_bytes = 16;
  nlohmann::json j{{"world_file", meta.worldFile},
                   {"project_root", meta.projectRoot},
                   {"seed", meta.seed},
                   {"seed_given", meta.seedGiven},
                   {"params", meta.params},
                   {"dt", meta.dt},
                   {"arguments", meta.arguments},
                   {"version", meta.version}};
  const std::string text = j.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
  chunk(kMeta, std::vector<uint8_t>(text.begin(), text.end()));
  std::vector<uint8_t> raw;
  Out o{raw};
  putLayout(o, layout);
  chunk(kLayout, raw);
  m_prev.assign(stateBytes(layout), 0);
  return true;
}

void RecordingWriter::frame(const SceneState& s, const FrameEvents& events) {
  if (!m_file || m_failed) return;
  m_cur.clear();
  Out state{m_cur};
  putState(state, s);
  const bool key = m_frames % kKeyFrameInterval == 0;
  m_raw.clear();
  Out o{m_raw};
  o.put(s.time);
  o.put(int64_t(s.steps));
  o.put(int32_t(s.faults));
  o.put(uint8_t(key));
  o.put(uint32_t(events.docks.size()));
  for (const DockEvent& e : events.docks) {
    o.put(e.time);
    o.str(dockEventName(e.kind));
    o.put(int32_t(e.moduleA));
    o.put(int32_t(e.dockA));
    o.put(int32_t(e.moduleB));
    o.put(int32_t(e.dockB));
    o.put(e.force);
    o.put(e.torque);
  }
  o.put(uint32_t(events.faults.size()));
  for (const auto& [module, text] : events.faults) {
    o.put(int32_t(module));
    o.str(text);
  }
  const size_t at = m_raw.size();
  m_raw.resize(at + m_cur.size());
  if (!key && m_prev.size() == m_cur.size())
    for (size_t i = 0; i < m_cur.size(); ++i) m_prev[i] ^= m_cur[i];  // m_prev is replaced below
  shuffle(key ? m_cur.data() : m_prev.data(), m_raw.data() + at, m_cur.size());
  m_prev.swap(m_cur);
  chunk(kFrame, m_raw);
  ++m_frames;
}

bool RecordingWriter::finish(const std::vector<std::pair<std::string, std::string>>& sources,
                             std::string& err) {
  if (!m_file) return true;
  std::vector<uint8_t> raw;
  Out o{raw};
  o.put(uint32_t(sources.size()));
  for (const auto& [path, text] : sources) {
    o.str(path);
    o.str(text);
  }
  chunk(kSources, raw);
  raw.clear();
  o.put(int64_t(m_frames));
  chunk(kEnd, raw);
  const bool closed = std::fclose(m_file) == 0;
  m_file = nullptr;
  if (m_failed || !closed) {
    err = "--record " + m_path + ": cannot write the file (disk full?)";
    return false;
  }
  return true;
}

// --- reading ---

bool Recording::unpack(const Packed& p, std::vector<uint8_t>& raw, std::string& err) const {
  raw.resize(p.rawSize);
  uLongf size = uLongf(p.rawSize);
  if (uncompress(raw.data(), &size, p.data.data(), uLong(p.data.size())) != Z_OK || size != p.rawSize ||
      uint32_t(crc32(0, raw.data(), uInt(raw.size()))) != p.crc) {
    err = m_path + ": damaged recording (a chunk fails its zlib or CRC-32 check)";
    return false;
  }
  return true;
}

bool Recording::load(const std::string& path, std::string& err) {
  m_path = path;
  std::FILE* f = std::fopen(path.c_str(), "rb");
  if (!f) {
    err = path + ": cannot read the recording (" + std::strerror(errno) + ")";
    return false;
  }
  std::unique_ptr<std::FILE, int (*)(std::FILE*)> closer(f, &std::fclose);
  char magic[8] = {};
  uint32_t version = 0, reserved = 0;
  const size_t got = std::fread(magic, 1, 8, f);
  if (got < 8 || std::memcmp(magic, kMagic, 8) != 0) {
    err = path +
          ": not an RM3D recording (expected a file written by `rm3d run --record`, starting with RM3DREC)";
    return false;
  }
  if (std::fread(&version, 4, 1, f) != 1 || std::fread(&reserved, 4, 1, f) != 1) {
    err = path + ": truncated recording (the file ends inside its 16-byte header)";
    return false;
  }
  if (version != kRecordingVersion) {
    err = path + ": recording format version " + std::to_string(version) + " (this rm3d reads version " +
          std::to_string(kRecordingVersion) + ")";
    return false;
  }
  // Every size field is checked against what the file really holds before anything is allocated.
  std::error_code ec;
  const uint64_t fileSize = std::filesystem::file_size(path, ec);
  if (ec) {
    err = path + ": cannot read the recording (" + ec.message() + ")";
    return false;
  }
  bool haveMeta = false, haveLayout = false, haveEnd = false;
  uint64_t offset = 16;
  int64_t endFrames = -1;
  for (;;) {
    uint32_t t = 0, crc = 0;
    uint64_t rawSize = 0, packedSize = 0;
    const size_t n = std::fread(&t, 1, 4, f);
    if (n == 0 && std::feof(f)) break;
    if (n != 4 || std::fread(&crc, 4, 1, f) != 1 || std::fread(&rawSize, 8, 1, f) != 1 ||
        std::fread(&packedSize, 8, 1, f) != 1) {
      err = path + ": truncated recording (the file ends inside a chunk header at byte " +
            std::to_string(offset) + "; expected " +
            (haveEnd ? "nothing more" : "more frames and the END_ chunk a finished run writes") + ")";
      return false;
    }
    if (rawSize > kMaxChunk || packedSize > kMaxChunk || packedSize > compressBound(uLong(rawSize)) + 64 ||
        rawSize > packedSize * kMaxRatio + 64) {
      err =
          path + ": damaged recording (a chunk at byte " + std::to_string(offset) + " has impossible sizes)";
      return false;
    }
    if (packedSize > fileSize - std::min(fileSize, offset + 24)) {
      err = path + ": truncated recording (the " + tagName(t) + " chunk at byte " + std::to_string(offset) +
            " claims " + std::to_string(packedSize) + " bytes, the file has " +
            std::to_string(fileSize - std::min(fileSize, offset + 24)) + " left; was the run killed?)";
      return false;
    }
    Packed p;
    p.crc = crc;
    p.rawSize = rawSize;
    p.data.resize(packedSize);
    if (packedSize && std::fread(p.data.data(), 1, packedSize, f) != packedSize) {
      err = path + ": truncated recording (the " + tagName(t) + " chunk at byte " + std::to_string(offset) +
            " needs " + std::to_string(packedSize) + " bytes, the file ends first; was the run killed?)";
      return false;
    }
    offset += 24 + packedSize;
    if (haveEnd) {
      err = path + ": damaged recording (data after the END_ chunk at byte " + std::to_string(offset) + ")";
      return false;
    }
    if (t == kFrame) {
      if (!haveLayout) {
        err = path + ": damaged recording (a frame before the layout)";
        return false;
      }
      m_frames.push_back(std::move(p));
      continue;
    }
    std::vector<uint8_t> raw;
    if (!unpack(p, raw, err)) return false;
    In in{raw.data(), raw.size()};
    if (t == kMeta) {
      const auto j = nlohmann::json::parse(raw.begin(), raw.end(), nullptr, false);
      if (j.is_discarded() || !j.is_object()) {
        err = path + ": damaged recording (its META chunk is not JSON)";
        return false;
      }
      m_meta.worldFile = j.value("world_file", "");
      m_meta.projectRoot = j.value("project_root", "");
      m_meta.seed = j.value("seed", uint64_t(1));
      m_meta.seedGiven = j.value("seed_given", false);
      m_meta.dt = j.value("dt", 1.0 / 60);
      m_meta.version = j.value("version", "");
      if (j.contains("params") && j["params"].is_object())
        for (const auto& [k, v] : j["params"].items())
          if (v.is_string()) m_meta.params[k] = v.get<std::string>();
      if (j.contains("arguments") && j["arguments"].is_array())
        for (const auto& a : j["arguments"])
          if (a.is_string()) m_meta.arguments.push_back(a.get<std::string>());
      haveMeta = true;
    } else if (t == kLayout) {
      std::string why;
      if (!getLayout(in, m_layout, why)) {
        err = path + ": damaged recording (its layout chunk has " + why + ")";
        return false;
      }
      completeLayout(m_layout);
      haveLayout = true;
    } else if (t == kSources) {
      const uint32_t count = in.count(8);
      for (uint32_t i = 0; i < count && !in.bad; ++i) {
        std::string p = in.str();
        std::string text = in.str();
        m_sources.emplace_back(std::move(p), std::move(text));
      }
      if (in.bad) {
        err = path + ": damaged recording (its SRCS chunk ends early)";
        return false;
      }
    } else if (t == kEnd) {
      endFrames = in.get<int64_t>();
      haveEnd = true;
    }
    // Unknown chunks are skipped: a later minor addition stays readable.
  }
  if (!haveMeta || !haveLayout) {
    err = path + ": truncated recording (expected META and LAYO chunks after the header)";
    return false;
  }
  if (!haveEnd) {
    err = path + ": truncated recording (" + std::to_string(m_frames.size()) +
          " frames, then the file ends without the END_ chunk a finished run writes; was the run killed?)";
    return false;
  }
  if (endFrames != int64_t(m_frames.size()) || m_frames.empty()) {
    err = path + ": damaged recording (the END_ chunk counts " + std::to_string(endFrames) +
          " frames, the file has " + std::to_string(m_frames.size()) + ")";
    return false;
  }
  return true;
}

int64_t Recording::frameAt(double t) const {
  const double i = std::round(t / m_layout.dt);
  if (!(i > 0)) return 0;
  return std::min<int64_t>(int64_t(std::min(i, 9e18)), frameCount() - 1);
}

bool Recording::frame(int64_t i, SceneState& out, FrameEvents* events, std::string& err) const {
  if (i < 0 || i >= frameCount()) {
    err = m_path + ": no frame " + std::to_string(i) + " (it has " + std::to_string(frameCount()) + ")";
    return false;
  }
  const size_t bytes = stateBytes(m_layout);
  // Start from the key frame at or before i, or from the cached frame when it is on the way.
  int64_t k = i - i % kKeyFrameInterval;
  if (m_cached >= k && m_cached < i) k = m_cached + 1;
  std::vector<uint8_t> raw;
  for (int64_t f = k; f <= i; ++f) {
    if (!unpack(m_frames[size_t(f)], raw, err)) return false;
    In in{raw.data(), raw.size()};
    out.time = in.get<double>();
    out.steps = in.get<int64_t>();
    out.faults = in.get<int32_t>();
    const bool key = in.get<uint8_t>() != 0;
    const uint32_t nd = in.count(32);
    if (events) events->docks.clear();
    for (uint32_t e = 0; e < nd; ++e) {
      DockEvent ev;
      ev.time = in.get<double>();
      if (!dockEventKindOf(in.str(), ev.kind)) in.bad = true;  // a name no build writes
      ev.moduleA = in.get<int32_t>();
      ev.dockA = in.get<int32_t>();
      ev.moduleB = in.get<int32_t>();
      ev.dockB = in.get<int32_t>();
      ev.force = in.get<double>();
      ev.torque = in.get<double>();
      if (events && f == i) events->docks.push_back(ev);
    }
    const uint32_t nf = in.count(8);
    if (events) events->faults.clear();
    for (uint32_t e = 0; e < nf; ++e) {
      const int m = in.get<int32_t>();
      std::string text = in.str();
      if (events && f == i) events->faults.emplace_back(m, std::move(text));
    }
    if (in.bad || in.n - in.at != bytes || (!key && m_cached != f - 1)) {
      err = m_path + ": damaged recording (frame " + std::to_string(f) + " does not fit the layout)";
      m_cached = -1;
      return false;
    }
    std::vector<uint8_t>& plain = m_scratch;
    plain.resize(bytes);
    unshuffle(raw.data() + in.at, plain.data(), bytes);
    if (key)
      m_cachedState = plain;
    else
      for (size_t b = 0; b < bytes; ++b) m_cachedState[b] ^= plain[b];
    m_cached = f;
  }
  In state{m_cachedState.data(), m_cachedState.size()};
  getState(state, m_layout, out);
  return true;
}

}  // namespace rm3d
