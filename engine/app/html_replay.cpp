// The HTML replay: the page template (html_replay/page.html, embedded at build time) with
// three.js and a JSON object of the run inlined. The JSON holds the layout (meshes once, items,
// modules, cloths, particle sets) and the kept frames as streams: per frame a row of integers
// (link and body positions in units of `unit` metres as int32; their quaternions x, y, z, w
// times 32767 as int16, signs chosen to follow the frame before; joint angles wrapped to
// (-pi, pi] times 32767 / pi as int16; cloth nodes and particle centres as int32 in `unit`);
// every row but the first holds its difference to the row before (wrapping), the bytes are
// regrouped in byte planes, deflated (zlib) and base64-encoded. The page inflates them with the
// browser's DecompressionStream. Dock and fault flags are kept as the first frame's and a list
// of changes; dock events with their times; the automatic camera per kept frame (float32).
#include "app/html_replay.h"

#include <zlib.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <type_traits>

#include "app/data_root.h"
#include "core/source_files.h"

namespace rm3d {

extern const char kHtmlReplayPage[];  // html_replay/page.html (generated at build time)

namespace {

constexpr double kPositionUnit = 1e-4;  // 0.1 mm

std::string base64(const uint8_t* data, size_t n) {
  static constexpr char kAlphabet[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((n + 2) / 3 * 4);
  size_t i = 0;
  for (; i + 2 < n; i += 3) {
    const uint32_t v = uint32_t(data[i]) << 16 | uint32_t(data[i + 1]) << 8 | data[i + 2];
    for (int k = 3; k >= 0; --k) out += kAlphabet[(v >> (6 * k)) & 63];
  }
  if (i < n) {
    const uint32_t v = uint32_t(data[i]) << 16 | (i + 1 < n ? uint32_t(data[i + 1]) << 8 : 0);
    out += kAlphabet[(v >> 18) & 63];
    out += kAlphabet[(v >> 12) & 63];
    out += i + 1 < n ? kAlphabet[(v >> 6) & 63] : '=';
    out += '=';
  }
  return out;
}

template <class T>
std::string base64Of(const std::vector<T>& v) {
  return base64(reinterpret_cast<const uint8_t*>(v.data()), v.size() * sizeof(T));
}

/// zlib-deflated (the format DecompressionStream('deflate') reads), base64-encoded.
bool deflated(const uint8_t* data, size_t n, std::string& out) {
  uLongf packedSize = compressBound(uLong(n));
  std::vector<uint8_t> packed(packedSize);
  if (compress2(packed.data(), &packedSize, data, uLong(n), 6) != Z_OK) return false;
  out = base64(packed.data(), packedSize);
  return true;
}

/// A [rows][columns] integer table as the page reads it: deltas over rows, byte planes, deflated.
template <class T>
bool packStream(std::vector<T>& table, size_t columns, nlohmann::json& out, double unit) {
  out = {{"columns", columns}, {"unit", unit}, {"data", ""}};
  if (columns == 0 || table.empty()) return true;
  using U = std::make_unsigned_t<T>;
  for (size_t i = table.size(); i-- > columns;)
    table[i] = T(U(U(table[i]) - U(table[i - columns])));  // wraps, as the page's typed arrays do
  const size_t n = table.size();
  const uint8_t* bytes = reinterpret_cast<const uint8_t*>(table.data());
  std::vector<uint8_t> planes(n * sizeof(T));
  for (size_t i = 0; i < n; ++i)
    for (size_t k = 0; k < sizeof(T); ++k) planes[k * n + i] = bytes[i * sizeof(T) + k];
  std::string data;
  if (!deflated(planes.data(), planes.size(), data)) return false;
  out["data"] = std::move(data);
  return true;
}

int32_t fixed(double v) {
  const double q = std::round(v / kPositionUnit);
  if (!(q == q)) return 0;  // NaN (a lost particle)
  return int32_t(std::clamp(q, -2147483647.0, 2147483647.0));
}

int16_t unitShort(double v) {
  return int16_t(std::lround(std::clamp(v, -1.0, 1.0) * 32767));
}

nlohmann::json color(const std::array<float, 4>& c) {
  return {c[0], c[1], c[2], c[3]};
}

/// The rows of the pose streams for one frame.
struct Rows {
  std::vector<int32_t> pos, points;
  std::vector<int16_t> rot, joints;
  std::vector<Quat> lastRot;  // for sign continuity

  void add(const Pose& p, size_t k) {
    pos.push_back(fixed(p.pos.x()));
    pos.push_back(fixed(p.pos.y()));
    pos.push_back(fixed(p.pos.z()));
    Quat q = p.rot;
    if (k < lastRot.size() && q.coeffs().dot(lastRot[k].coeffs()) < 0) q.coeffs() = -q.coeffs();
    if (k >= lastRot.size()) lastRot.resize(k + 1);
    lastRot[k] = q;
    for (double c : {q.x(), q.y(), q.z(), q.w()}) rot.push_back(unitShort(c));
  }
  void addPoint(const Eigen::Vector3f& v) {
    for (int i = 0; i < 3; ++i) points.push_back(fixed(double(v[i])));
  }
};

std::string pageTitle(const Recording& rec) {
  const std::string world = std::filesystem::path(rec.meta().worldFile).filename().string();
  return (world.empty() ? std::string("recording") : world) + " - RM3D replay";
}

std::string htmlEscaped(const std::string& s) {
  std::string out;
  for (char c : s) {
    if (c == '<')
      out += "&lt;";
    else if (c == '>')
      out += "&gt;";
    else if (c == '&')
      out += "&amp;";
    else
      out += c;
  }
  return out;
}

// three.min.js is about 0.6 MiB; a file far larger is not a three.js build (RM3D_THREE_JS=/dev/zero
// once read until memory ran out).
constexpr std::uintmax_t kThreeJsMaxBytes = 64u << 20;

bool readThreeJs(std::string& text, std::string& err) {
  const char* path = htmlThreeJsPath();
  std::error_code ec;
  const bool regular = std::filesystem::is_regular_file(path, ec);
  if (!regular && std::filesystem::exists(path, ec)) {
    err = std::string(path) + ": not a regular file (expected three.js, e.g. three.min.js)";
    return false;
  }
  if (regular) {
    const std::uintmax_t size = std::filesystem::file_size(path, ec);
    if (!ec && size > kThreeJsMaxBytes) {
      err = std::string(path) + ": " + std::to_string(size >> 20) + " MiB, more than the " +
            std::to_string(kThreeJsMaxBytes >> 20) + " MiB a three.js build can be";
      return false;
    }
  }
  std::ifstream f(path, std::ios::binary);
  std::ostringstream s;
  if (f) s << f.rdbuf();
  if (!f || s.str().empty()) {
    err = std::string("three.js is not at ") + path +
          " (install the Debian package libjs-three: apt-get install libjs-three)";
    return false;
  }
  text = s.str();
  std::string lower = text;
  std::transform(lower.begin(), lower.end(), lower.begin(),
                 [](unsigned char c) { return char(std::tolower(c)); });
  // Either would end the page's script element, or change how the rest of it is read.
  for (const char* bad : {"</script", "<!--"}) {
    if (lower.find(bad) != std::string::npos) {
      err = std::string(path) + ": contains '" + bad + "', which cannot be inlined in a page";
      return false;
    }
  }
  return true;
}

}  // namespace

const char* htmlThreeJsPath() {
  const char* env = std::getenv("RM3D_THREE_JS");
  return env && *env ? env : RM3D_THREE_JS;
}

bool htmlReplayReady(std::string& err) {
  std::string text;
  return readThreeJs(text, err);
}

bool writeHtmlReplay(const Recording& rec, const SceneLayout::CameraDef& camera, const std::string& out,
                     HtmlReplayStats& stats, std::string& err) {
  std::string three;
  if (!readThreeJs(three, err)) {
    err = "--html " + out + ": " + err;
    return false;
  }
  SceneLayout lay = rec.layout();
  lay.camera = camera;
  const int64_t recorded = rec.frameCount();
  size_t pointCount = 0;
  for (const SceneLayout::Cloth& c : lay.cloths) pointCount += size_t(c.nodes);
  for (const SceneLayout::Particles& p : lay.particles) pointCount += size_t(p.count);
  const size_t poseCount = size_t(lay.linkCount) + lay.bodyRadius.size();
  const int64_t perFrame = int64_t(std::max<size_t>(1, poseCount + pointCount));
  const int stride = int(std::max<int64_t>(1, (recorded * perFrame + kHtmlPoseBudget - 1) / kHtmlPoseBudget));
  std::vector<int64_t> kept;
  for (int64_t i = 0; i < recorded; i += stride) kept.push_back(i);
  if (kept.back() != recorded - 1) kept.push_back(recorded - 1);

  nlohmann::json j;
  j["title"] = pageTitle(rec);
  // What the world shows, in its own words: the first sentence of its opening comment.
  std::string about;
  if (!rec.meta().worldFile.empty()) {
    const std::string key = SourceFiles::key(rec.meta().worldFile);
    for (const auto& [path, text] : rec.sources())
      if (path == key) about = worldSummary(text, 400);
  }
  j["about"] = about;
  j["dt"] = lay.dt;
  j["recordedFrames"] = recorded;
  j["stride"] = stride;
  j["fov"] = camera.fovDeg;
  j["ground"] = lay.ground;
  j["links"] = lay.linkCount;
  j["bodies"] = lay.bodyRadius.size();
  j["dockCount"] = lay.dockCount;
  j["jointCount"] = lay.jointCount;
  j["pointCount"] = pointCount;
  j["colors"] = {{"fault", color(kFaultColor)},
                 {"dockDisabled", color(kDockDisabledColor)},
                 {"dockFree", color(kDockFreeColor)},
                 {"dockEngaged", color(kDockEngagedColor)}};
  int dockMesh = 0;
  nlohmann::json meshes = nlohmann::json::array(), items = nlohmann::json::array();
  for (const RenderMesh& m : lay.meshes) {
    std::vector<float> v;
    for (const Eigen::Vector3f& p : m.vertices) v.insert(v.end(), {p.x(), p.y(), p.z()});
    meshes.push_back({{"vertices", base64Of(v)}, {"indices", base64Of(m.indices)}});
  }
  // Items as [template, owner] pairs: the modules of one type share their items but for the owner.
  std::map<std::string, int> templates;
  nlohmann::json itemTypes = nlohmann::json::array();
  for (size_t i = 0; i < lay.items.size(); ++i) {
    const SceneLayout::Item& it = lay.items[i];
    const Pose& l = it.local;
    const Eigen::Vector2f reach = i < lay.dockReach.size() ? lay.dockReach[i] : Eigen::Vector2f::Zero();
    nlohmann::json t = {
        {"kind", int(it.kind)},
        {"reach", {reach.x(), reach.y()}},
        {"link", it.link},
        {"dock", it.dock},
        {"mesh", it.mesh},
        {"local", {l.pos.x(), l.pos.y(), l.pos.z(), l.rot.w(), l.rot.x(), l.rot.y(), l.rot.z()}},
        {"scale", {it.scale.x(), it.scale.y(), it.scale.z()}},
        {"color", color(it.color)}};
    const auto [at, added] = templates.emplace(t.dump(), int(itemTypes.size()));
    if (added) itemTypes.push_back(std::move(t));
    items.push_back(at->second);
    items.push_back(it.owner);
    if (it.kind == SceneLayout::Kind::Dock) dockMesh = it.mesh;
  }
  j["meshes"] = std::move(meshes);
  j["itemTypes"] = std::move(itemTypes);
  j["itemList"] = std::move(items);
  j["dockMark"] = {{"mesh", dockMesh},
                   {"shift", kDockMark.shift},
                   {"depth", kDockMark.depth},
                   {"overhang", kDockMark.overhang},
                   {"thickness", kDockMark.thickness}};
  nlohmann::json modules = nlohmann::json::array();
  for (const SceneLayout::ModuleInfo& m : lay.modules)
    modules.push_back({{"name", m.name},
                       {"type", m.type},
                       {"id", m.id},
                       {"rootLink", m.rootLink},
                       {"firstLink", m.firstLink},
                       {"firstJoint", m.firstJoint},
                       {"firstDock", m.firstDock},
                       {"joints", m.joints},
                       {"docks", m.docks}});
  j["modules"] = std::move(modules);
  j["cloths"] = nlohmann::json::array();
  for (const SceneLayout::Cloth& c : lay.cloths)
    j["cloths"].push_back(
        {{"nodes", c.nodes}, {"triangles", base64Of(c.triangles)}, {"color", color(c.color)}});
  j["particles"] = nlohmann::json::array();
  for (const SceneLayout::Particles& p : lay.particles)
    j["particles"].push_back({{"count", p.count}, {"radius", p.radius}, {"color", color(p.color)}});

  // Every recorded frame is read (dock events happen at any step); the kept ones go in the streams.
  Rows rows;
  std::vector<float> cams;
  nlohmann::json events = nlohmann::json::array(), dockChanges = nlohmann::json::array(),
                 faultChanges = nlohmann::json::array(), frameSteps = nlohmann::json::array();
  SceneState start, st;
  std::vector<uint8_t> docks, faulted;
  FrameEvents ev;
  size_t next = 0;
  for (int64_t i = 0; i < recorded; ++i) {
    if (!rec.frame(i, i == 0 ? start : st, &ev, err)) {
      err = "--html " + out + ": " + err;
      return false;
    }
    const SceneState& s = i == 0 ? start : st;
    for (const DockEvent& e : ev.docks)
      events.push_back(
          {e.time, dockEventName(e.kind), e.moduleA, e.dockA, e.moduleB, e.dockB, e.force, e.torque, i == 0});
    if (next >= kept.size() || kept[next] != i) continue;
    const int f = int(next++);
    frameSteps.push_back(s.steps);
    for (size_t k = 0; k < s.links.size(); ++k) rows.add(s.links[k], k);
    for (size_t k = 0; k < s.bodies.size(); ++k) rows.add(s.bodies[k], s.links.size() + k);
    for (double a : s.joints) rows.joints.push_back(unitShort(std::remainder(a, 2 * kPi) / kPi));
    for (const Eigen::Vector3f& v : s.clothNodes) rows.addPoint(v);
    for (const Eigen::Vector3f& v : s.particles) rows.addPoint(v);
    const Camera cam = sceneCamera(lay, start, s);
    cams.insert(cams.end(),
                {cam.eye.x(), cam.eye.y(), cam.eye.z(), cam.target.x(), cam.target.y(), cam.target.z()});
    if (f == 0) {
      docks = s.docks;
      faulted = s.faulted;
      j["dockStart"] = docks;
      j["faultStart"] = faulted;
      continue;
    }
    for (size_t d = 0; d < docks.size() && d < s.docks.size(); ++d)
      if (s.docks[d] != docks[d]) dockChanges.push_back({f, d, s.docks[d]}), docks[d] = s.docks[d];
    for (size_t m = 0; m < faulted.size() && m < s.faulted.size(); ++m)
      if (s.faulted[m] != faulted[m]) faultChanges.push_back({f, m, s.faulted[m]}), faulted[m] = s.faulted[m];
  }
  j["frameSteps"] = std::move(frameSteps);
  j["events"] = std::move(events);
  j["dockChanges"] = std::move(dockChanges);
  j["faultChanges"] = std::move(faultChanges);
  nlohmann::json pos, rot, joints, points;
  std::string camData;
  if (!packStream(rows.pos, poseCount * 3, pos, kPositionUnit) ||
      !packStream(rows.rot, poseCount * 4, rot, 1) ||
      !packStream(rows.joints, size_t(lay.jointCount), joints, 1) ||
      !packStream(rows.points, pointCount * 3, points, kPositionUnit) ||
      !deflated(reinterpret_cast<const uint8_t*>(cams.data()), cams.size() * sizeof(float), camData)) {
    err = "--html " + out + ": could not compress the frames (out of memory?)";
    return false;
  }
  j["pos"] = std::move(pos);
  j["rot"] = std::move(rot);
  j["joints"] = std::move(joints);
  j["points"] = std::move(points);
  j["camera"] = std::move(camData);

  // Every "<" written as "\u003c" (the same JSON string): "</script" would end the <script>
  // element, and "<!--" followed by "<script" makes the browser read the rest of the page as
  // part of it (a module named "<!--<script>" once swallowed the page's code). JSON has "<"
  // only inside strings.
  std::string data = j.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
  for (size_t at = 0; (at = data.find('<', at)) != std::string::npos; at += 6) data.replace(at, 1, "\\u003c");

  std::string page = kHtmlReplayPage;
  const size_t titleAt = page.find("@TITLE@");
  if (titleAt != std::string::npos) page.replace(titleAt, 7, htmlEscaped(pageTitle(rec)));
  // Both markers found in the template first, then filled from the later one back: a three.js
  // file that itself holds "/*@DATA@*/" must not get the data spliced into it.
  const std::string threeMarker = "/*@THREE@*/", dataMarker = "/*@DATA@*/";
  const size_t threeAt = page.find(threeMarker), dataAt = page.find(dataMarker);
  if (threeAt == std::string::npos || dataAt == std::string::npos) {
    err = "--html " + out + ": the page template lacks " +
          (threeAt == std::string::npos ? threeMarker : dataMarker);
    return false;
  }
  if (threeAt > dataAt) {
    page.replace(threeAt, threeMarker.size(), three);
    page.replace(dataAt, dataMarker.size(), data);
  } else {
    page.replace(dataAt, dataMarker.size(), data);
    page.replace(threeAt, threeMarker.size(), three);
  }

  // Written next to OUT first and renamed, so a failed write leaves no half page behind.
  const std::string tmp = out + ".tmp";
  {
    std::ofstream f(tmp, std::ios::binary);
    f.write(page.data(), std::streamsize(page.size()));
    f.close();
    if (!f) {
      std::error_code ec;
      std::filesystem::remove(tmp, ec);
      err = "--html " + out + ": cannot write the file";
      return false;
    }
  }
  std::error_code ec;
  std::filesystem::rename(tmp, out, ec);
  if (ec) {
    std::filesystem::remove(tmp, ec);
    err = "--html " + out + ": cannot write the file (" + ec.message() + ")";
    return false;
  }
  stats.recordedFrames = recorded;
  stats.keptFrames = int64_t(kept.size());
  stats.stride = stride;
  stats.bytes = page.size();
  return true;
}

}  // namespace rm3d
