// The public engine API's Simulation: a World with its sources, its agents' arrays, its
// recording and the log that makes a snapshot (docs/python.md, "Snapshots").
//
// A snapshot is the run's inputs, not a dump of its memory: the world (path or source), the Lua
// texts it read, seed and params, how many steps ran, the actions applied at each step, and the
// steps at which the arrays were read (observe(), world.reward and world.done are Lua calls that
// may change a script's state). Restoring loads the world with those texts and runs it again
// to the same step with the same calls; the engine is deterministic, so the result is the
// original's bit for bit, in this process or another, at any thread count. Bullet's contact
// caches, the Lua heaps and every RNG stream are therefore exactly as they were, with nothing
// to serialise; the cost is time: a restore re-runs the steps (an 8-module chain: about
// 30 000 steps a second).
#include "rm3d/simulation.h"

#include <dlfcn.h>
#include <zlib.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "assets/mesh_loader.h"
#include "core/error.h"
#include "core/path_rule.h"
#include "core/source_files.h"
#include "core/text_file.h"
#include "io/run_capture.h"
#include "io/scene_state.h"
#include "io/summary.h"
#include "render/offscreen_renderer.h"
#include "script/world_script.h"
#include "world/world.h"

namespace fs = std::filesystem;

namespace rm3d::api {

namespace {

bool isDataRoot(const fs::path& dir) {
  std::error_code ec;
  return fs::is_directory(dir / "assets" / "modules", ec);
}

/// The project root: given; $RM3D_ROOT; the nearest folder above the world holding assets/modules;
/// the nearest above the working folder; the installed data; the source tree this was built from.
std::string findRoot(const Options& o, const std::string& world) {
  std::error_code ec;
  if (!o.root.empty()) {
    if (!isDataRoot(o.root))
      throw Error("root=" + o.root + ": not an RM3D project (no assets/modules folder)");
    return fs::weakly_canonical(fs::absolute(o.root, ec), ec).string();
  }
  if (const char* env = std::getenv("RM3D_ROOT"); env && *env) {
    if (!isDataRoot(env))
      throw Error(std::string("RM3D_ROOT=") + env + ": not an RM3D project (no assets/modules folder)");
    return fs::weakly_canonical(fs::absolute(env, ec), ec).string();
  }
  auto upFrom = [&](fs::path p) -> std::string {
    for (; !p.empty(); p = p.parent_path()) {
      if (isDataRoot(p)) return p.string();
      if (p == p.parent_path()) break;
    }
    return "";
  };
  if (!world.empty())
    if (std::string r = upFrom(fs::path(world).parent_path()); !r.empty()) return r;
  if (std::string r = upFrom(fs::current_path(ec)); !r.empty()) return r;
  // Installed: <prefix>/share/rm3d above the file this code is in (the Python extension, or rm3d).
  Dl_info info{};
  if (dladdr(reinterpret_cast<void*>(&isDataRoot), &info) && info.dli_fname)
    for (fs::path p = fs::absolute(info.dli_fname, ec).parent_path(); !p.empty(); p = p.parent_path()) {
      if (isDataRoot(p / "share" / "rm3d")) return (p / "share" / "rm3d").string();
      if (p == p.parent_path()) break;
    }
#ifdef RM3D_SOURCE_DIR
  if (isDataRoot(RM3D_SOURCE_DIR)) return RM3D_SOURCE_DIR;
#endif
  throw Error("no RM3D project found for " + (world.empty() ? std::string("the world") : world) +
              ": pass root= (a folder holding assets/modules) or set RM3D_ROOT");
}

RunOptions runOptions(const Options& o, const std::string& root) {
  if (o.threads < 1 || o.threads > 256)
    throw Error("threads=" + std::to_string(o.threads) + ": expected a whole number from 1 to 256");
  for (const auto& [k, v] : o.params)
    if (k.empty()) throw Error("params: a key is empty; expected names such as modules=10");
  RunOptions r;
  r.projectRoot = root;
  r.params = o.params;
  r.seed = o.seed;
  r.strict = o.strict;
  r.threads = o.threads;
  r.echoLog = o.echo;
  r.echoWorldLog = o.echo;
  r.sources = std::make_shared<SourceFiles>();
  return r;
}

// Little-endian packing for the snapshot.
void put64(std::string& s, uint64_t v) {
  for (int i = 0; i < 8; ++i) s.push_back(char((v >> (8 * i)) & 0xff));
}
uint64_t get64(const std::string& s, size_t& at) {
  if (at + 8 > s.size()) throw Error("snapshot: the bytes end early (truncated or not a snapshot)");
  uint64_t v = 0;
  for (int i = 0; i < 8; ++i) v |= uint64_t(uint8_t(s[at + size_t(i)])) << (8 * i);
  at += 8;
  return v;
}
constexpr char kMagic[] = "RM3DSNP1";

}  // namespace

struct Simulation::Impl {
  Options options;
  std::string root;
  std::string path;          ///< absolute world file; empty for a source world
  std::string source, name;  ///< a source world's text and name
  std::unique_ptr<World> world;
  std::shared_ptr<SourceFiles> sources;
  std::shared_ptr<rm3d::MeshCache> meshes;  ///< kept across restores (and shared in a Batch)
  std::shared_ptr<AgentArrays> own = std::make_shared<AgentArrays>();
  std::shared_ptr<AgentArrays> target;  ///< own, or a batch's
  int rowOffset = 0;
  int rowLimit = -1;  ///< rows of the target that are this world's (-1: own arrays, all)
  int64_t refreshedAt = -1;
  std::vector<std::vector<double>> rows;  ///< observe() scratch, per module
  std::vector<double> rewardRow;          ///< world.reward / world.done scratch
  std::vector<uint8_t> doneRow;
  bool closed = false, ended = false;
  double wallSeconds = 0;
  std::unique_ptr<RunCapture> capture;
  /// render(): the renderer (an OSMesa context, made at the first render) and the scene as it was
  /// then (the automatic camera frames it).
  struct Picture {
    OffscreenRenderer renderer;
    SceneLayout layout;
    SceneState start, now;
    bool started = false;
  };
  std::unique_ptr<Picture> picture;
  // The log (see the top of this file): actions by step, and the steps the arrays were read at.
  struct Act {
    int64_t step;
    int rows, stride;
    size_t at;  ///< into actData
  };
  std::vector<Act> acts;
  std::vector<double> actData;
  std::vector<int64_t> reads;

  void check() const {
    if (closed) throw Error("this world is closed");
  }
  AgentArrays& arr() { return *target; }
  /// Rows of the target this world may write.
  int capacity() const { return rowLimit >= 0 ? rowLimit : target->rows; }

  void load() {
    RunOptions ro = runOptions(options, root);
    if (sources) ro.sources = sources;
    sources = ro.sources;
    if (!meshes) meshes = std::make_shared<rm3d::MeshCache>();
    ro.meshes = meshes;
    world = std::make_unique<World>(ro);
    try {
      if (!path.empty()) {
        std::error_code ec;
        // A snapshot's world text is in its overlay: the file itself may be gone.
        if (!(sources && sources->overlaid(path)) && !fs::is_regular_file(path, ec))
          throw Error(path + ": cannot read world file (" +
                      (fs::exists(path, ec) ? "not a regular file" : "no such file") + ")");
        world->loadFile(path);
      } else {
        world->loadString(source, name);
      }
      world->start();
    } catch (const InputError& e) {
      throw Error(e.what());
    }
    if (!world->scriptError().empty()) throw Error(world->scriptError());
    target = own;
  }

  /// Sizes this world needs: modules, max obs row, max act row (observing now).
  void observeAll() {
    const int n = int(world->modules().size());
    rows.resize(size_t(n));
    world->forEachModule([this](int i) { world->observe(i, rows[size_t(i)]); });
  }

  /// Observes, then writes obs/act sizes, reward and done into the target arrays.
  void refresh() {
    if (refreshedAt == world->steps()) return;
    refreshedAt = world->steps();
    if (options.snapshots) reads.push_back(refreshedAt);
    observeAll();
    const int n = int(rows.size());
    int obsDim = 0, actDim = 0;
    for (int i = 0; i < n; ++i) {
      obsDim = std::max(obsDim, int(rows[size_t(i)].size()));
      actDim = std::max(actDim, world->actSize(i));
    }
    if (target == own && (n != own->rows || obsDim > own->obsDim || actDim > own->actDim))
      resizeOwn(n, obsDim, actDim);
    AgentArrays& a = arr();
    const int avail = std::max(0, std::min(n, capacity()));
    for (int i = 0; i < avail; ++i) {
      const size_t r = size_t(rowOffset + i);
      std::vector<double>& row = rows[size_t(i)];
      if (int(row.size()) > a.obsDim) {
        world->faultModule(i, "observe() returned " + std::to_string(row.size()) +
                                  " numbers; this batch's obs rows hold " + std::to_string(a.obsDim) +
                                  " (the largest of the first observations)");
        row.resize(size_t(a.obsDim));
      }
      double* o = a.obs.data() + r * size_t(a.obsDim);
      std::fill(o, o + a.obsDim, 0.0);
      std::copy(row.begin(), row.end(), o);
      a.obsSize[r] = int32_t(row.size());
      a.actSize[r] = int32_t(std::min(world->actSize(i), a.actDim));
      a.mask[r] = 1;
    }
    double* reward = a.reward.data() + rowOffset;
    uint8_t* done = a.done.data() + rowOffset;
    std::fill(reward, reward + avail, 0.0);
    std::fill(done, done + avail, uint8_t(0));
    WorldScript* s = world->script();
    std::string err;
    if (s && world->scriptError().empty() && avail > 0) {
      rewardRow.assign(size_t(n), 0.0);  // one per module, even those past the batch's rows
      doneRow.assign(size_t(n), 0);
      if (s->hasReward() && !s->reward(n, rewardRow.data(), err)) world->setScriptError(err);
      if (s->hasDone() && err.empty() && !s->done(n, doneRow.data(), err)) world->setScriptError(err);
      if (!err.empty()) {  // what a failing hook returned is not handed on (a NaN, half a list)
        std::fill(rewardRow.begin(), rewardRow.end(), 0.0);
        std::fill(doneRow.begin(), doneRow.end(), uint8_t(0));
      }
      std::copy_n(rewardRow.begin(), avail, reward);
      std::copy_n(doneRow.begin(), avail, done);
    }
  }

  void resizeOwn(int n, int obsDim, int actDim) {
    auto a = std::make_shared<AgentArrays>();
    a->rows = n;
    a->obsDim = std::max(obsDim, own->obsDim);
    a->actDim = std::max(actDim, own->actDim);
    a->obs.assign(size_t(n) * size_t(a->obsDim), 0.0);
    a->act.assign(size_t(n) * size_t(a->actDim), 0.0);
    for (int i = 0; i < std::min(n, own->rows); ++i)  // the actions written so far stay
      std::copy_n(own->act.data() + size_t(i) * size_t(own->actDim), own->actDim,
                  a->act.data() + size_t(i) * size_t(a->actDim));
    a->reward.assign(size_t(n), 0.0);
    a->done.assign(size_t(n), 0);
    a->mask.assign(size_t(n), 1);
    a->obsSize.assign(size_t(n), 0);
    a->actSize.assign(size_t(n), 0);
    own = a;
    target = own;
  }

  /// Raises Error where this world's action rows in the target arrays hold a NaN or an infinity.
  void checkActions() {
    AgentArrays& a = arr();
    const int n = std::min(int(world->modules().size()), capacity());
    if (n <= 0 || a.actDim == 0) return;
    const double* base = a.act.data() + size_t(rowOffset) * size_t(a.actDim);
    for (int i = 0; i < n; ++i) {
      const int used = std::min(world->actSize(i), a.actDim);
      for (int j = 0; j < used; ++j)
        if (!std::isfinite(base[size_t(i) * size_t(a.actDim) + size_t(j)])) {
          const double v = base[size_t(i) * size_t(a.actDim) + size_t(j)];
          throw Error("act[" + std::to_string(i) + "][" + std::to_string(j) + "] is " +
                      (std::isnan(v) ? "nan" : "infinite") + " (module " + world->module(i).name +
                      "): actions must be finite numbers");
        }
    }
  }

  /// The action rows of this world in the target arrays, checked finite.
  void applyActions(int64_t stepIndex) {
    checkActions();
    AgentArrays& a = arr();
    const int n = std::min(int(world->modules().size()), capacity());
    if (n <= 0 || a.actDim == 0) return;
    const double* base = a.act.data() + size_t(rowOffset) * size_t(a.actDim);
    if (options.snapshots) {
      acts.push_back({stepIndex, n, a.actDim, actData.size()});
      actData.insert(actData.end(), base, base + size_t(n) * size_t(a.actDim));
    }
    world->setActions(base, a.actDim, n);
  }

  void stepOnce(bool policy) {
    if (policy) applyActions(world->steps());
    world->step();
    if (capture) capture->step(*world);
  }

  void startRecording() {
    if (options.record.empty()) return;
    // The output rule of docs/limits.md: the recording may not overwrite the world script or any
    // file the world has read (its behaviours, module types, required files), through a link either.
    std::vector<NamedPath> inputs;
    if (!path.empty()) inputs.push_back({"the world script", path});
    for (const auto& [p, text] : sources->taken()) inputs.push_back({"a file the world read,", p});
    std::string clash;
    if (!checkOutputsApart(inputs, {{"record=", options.record}}, clash)) throw Error(clash);
    std::error_code ec;
    const fs::path folder = fs::path(options.record).parent_path();
    if (!folder.empty() && !fs::is_directory(folder, ec) && !fs::create_directories(folder, ec))
      throw Error("record=" + options.record + ": cannot create the folder " + folder.string() + " (" +
                  ec.message() + ")");
    RecordingMeta meta{path.empty() ? world->worldFile() : path,
                       root,
                       world->settings().seed,
                       options.seed.has_value(),
                       options.params,
                       0,
                       {"python", "rm3d.World"},
                       ""};
    capture = std::make_unique<RunCapture>(options.record, meta, CameraArgs{});
    capture->start(*world);
    if (!capture->error().empty()) throw Error("record=" + options.record + ": " + capture->error());
  }

  void endRecording() {
    if (!capture) return;
    std::string err;
    std::unique_ptr<RunCapture> c = std::move(capture);
    if (c->started() && !c->finish(sources->taken(), err))
      throw Error("record=" + options.record + ": " + err);
  }
};

Simulation::Simulation() : m(std::make_unique<Impl>()) {}
Simulation::~Simulation() {
  // A destructor cannot throw: a recording that cannot be finished is reported, not dropped silently.
  try {
    if (m && !m->closed) m->endRecording();
  } catch (const std::exception& e) {
    std::fprintf(stderr, "rm3d: %s\n", e.what());
  }
}

namespace {

/// A path holding a NUL would name another file to the operating system (everything after the
/// NUL dropped): refused, never shortened.
void checkNoNul(const std::string& value, const std::string& what) {
  if (const size_t at = value.find('\0'); at != std::string::npos)
    throw Error(what + ": holds a NUL character (byte " + std::to_string(at) + "); expected a file path");
}

void checkPaths(const Options& options) {
  checkNoNul(options.record, "record");
  checkNoNul(options.root, "root");
}

}  // namespace

std::unique_ptr<Simulation> Simulation::open(const std::string& path, const Options& options) {
  return open(path, options, nullptr);
}

std::unique_ptr<Simulation> Simulation::open(const std::string& path, const Options& options,
                                             std::shared_ptr<rm3d::MeshCache> meshes) {
  std::unique_ptr<Simulation> s(new Simulation());
  s->m->meshes = std::move(meshes);
  if (path.empty()) throw Error("path: empty; expected a world file (.lua)");
  checkNoNul(path, "path");
  checkPaths(options);
  std::error_code ec;
  // As `rm3d run` finds a world: the working folder, then the data root (the shipped worlds/).
  std::string found = path;
  if (!fs::path(path).is_absolute() && !fs::exists(path, ec)) {
    std::string root, note;
    try {
      root = findRoot(options, "");
    } catch (const Error&) {  // no data root: the path stays as given, and load() says it is missing
    }
    found = resolveWorldPath(path, root, &note);
    if (found == path && !note.empty()) throw Error(note);
  }
  const std::string abs = fs::absolute(found, ec).lexically_normal().string();
  s->m->options = options;
  s->m->path = abs;
  s->m->root = findRoot(options, abs);
  s->m->load();
  s->m->startRecording();
  return s;
}

std::unique_ptr<Simulation> Simulation::fromString(const std::string& source, const std::string& name,
                                                   const Options& options) {
  std::unique_ptr<Simulation> s(new Simulation());
  checkPaths(options);
  s->m->options = options;
  s->m->source = source;
  s->m->name = name.empty() ? "world" : name;
  s->m->root = findRoot(options, "");
  s->m->load();
  s->m->startRecording();
  return s;
}

void Simulation::step(int64_t n, const std::function<bool()>& interrupted) {
  m->check();
  if (n < 0) throw Error("step(n): n = " + std::to_string(n) + "; expected a whole number >= 0");
  if (m->ended)
    throw Error(
        "the world has finished (finish() ran its on_end hooks); fork() it or restore a snapshot to go on");
  const auto t0 = std::chrono::steady_clock::now();
  World& w = *m->world;
  try {
    for (int64_t k = 0; k < n && !w.stopped(); ++k) {
      if (interrupted && k > 0 && k % 64 == 0 && interrupted()) break;
      if (m->options.policy && m->refreshedAt < 0) m->refresh();  // the first step: sizes for the act rows
      m->stepOnce(m->options.policy);
    }
    if (m->options.policy) m->refresh();
  } catch (const InputError& e) {
    throw Error(e.what());
  } catch (const Error&) {
    throw;
  } catch (const std::exception& e) {
    throw Error(w.worldFile() + ": the run stopped at t=" + std::to_string(w.time()) + " s: " + e.what());
  }
  m->wallSeconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (!w.scriptError().empty()) throw Error(w.scriptError());
}

void Simulation::checkActions() {
  m->check();
  if (!m->options.policy || m->ended || m->world->stopped()) return;
  if (m->refreshedAt < 0) m->refresh();  // the first step: sizes for the act rows
  m->checkActions();
}

double Simulation::time() const {
  return m->world->time();
}
int64_t Simulation::steps() const {
  return m->world->steps();
}
double Simulation::dt() const {
  return m->world->settings().dt;
}
const std::string& Simulation::path() const {
  return m->path;
}
bool Simulation::finished() const {
  return m->ended || m->world->finished();
}
bool Simulation::stopped() const {
  return m->world->stopped();
}
int Simulation::moduleCount() const {
  return int(m->world->modules().size());
}

std::vector<std::string> Simulation::moduleNames() const {
  std::vector<std::string> out;
  for (const Module& mod : m->world->modules()) out.push_back(mod.name);
  return out;
}

std::string Simulation::summaryJson() const {
  m->check();
  return runSummary(*m->world, m->wallSeconds).dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

std::string Simulation::finish() {
  m->check();
  World& w = *m->world;
  std::vector<std::string> warnings;
  if (!m->ended) {
    m->ended = true;
    WorldScript* script = w.script();
    std::string err;
    if (script && w.scriptError().empty() && !script->atEnd(w.time(), err)) w.setScriptError(err);
    m->endRecording();
  }
  nlohmann::json j = runSummary(w, m->wallSeconds);
  if (WorldScript* script = w.script()) j["warnings"] = script->hooksNeverRun(w.time());
  return j.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

std::map<std::string, double> Simulation::metrics() const {
  return m->world->metrics();
}

std::map<std::string, std::string> Simulation::faults() const {
  std::map<std::string, std::string> out;
  for (const Module& mod : m->world->modules())
    if (!mod.fault.empty()) out[mod.name] = mod.fault;
  return out;
}

std::shared_ptr<AgentArrays> Simulation::arrays() {
  m->check();
  // A read refreshes the arrays, which calls observe() and the reward and done hooks: an error
  // they raise here is raised as step() raises it, not left in the world unseen.
  const bool failedBefore = !m->world->scriptError().empty();
  m->refresh();
  if (!failedBefore && !m->world->scriptError().empty()) throw Error(m->world->scriptError());
  return m->target;
}

void Simulation::bindArrays(std::shared_ptr<AgentArrays> target, int rowOffset, int rows) {
  Impl& i = *m;
  if (!target) {
    i.target = i.own;
    i.rowOffset = 0;
    i.rowLimit = -1;
    return;
  }
  // The rows read so far move over as they are (no new read: observe() may change a script's state).
  AgentArrays& t = *target;
  const AgentArrays& o = *i.own;
  if (o.obsDim > t.obsDim || o.actDim > t.actDim || o.rows > rows || rowOffset + rows > t.rows)
    throw Error("bindArrays: the world's arrays do not fit the target's");
  for (int r = 0; r < o.rows; ++r) {
    const size_t d = size_t(rowOffset + r);
    std::copy_n(o.obs.data() + size_t(r) * size_t(o.obsDim), o.obsDim, t.obs.data() + d * size_t(t.obsDim));
    t.obsSize[d] = o.obsSize[size_t(r)];
    t.actSize[d] = o.actSize[size_t(r)];
    t.reward[d] = o.reward[size_t(r)];
    t.done[d] = o.done[size_t(r)];
    t.mask[d] = 1;
  }
  i.target = std::move(target);
  i.rowOffset = rowOffset;
  i.rowLimit = rows;
}

int Simulation::obsDim() const {
  return m->own->obsDim;
}
int Simulation::actDim() const {
  return m->own->actDim;
}

std::vector<uint8_t> Simulation::render(int width, int height, const View& view) {
  m->check();
  constexpr int kMaxSide = 8192;
  constexpr int64_t kMaxPixels = int64_t(7680) * 4320;  // 8K: the buffers then take 400 MB
  if (width < 1 || width > kMaxSide || height < 1 || height > kMaxSide ||
      int64_t(width) * height > kMaxPixels)
    throw Error("render: " + std::to_string(width) + "x" + std::to_string(height) +
                ": expected a width and a height from 1 to " + std::to_string(kMaxSide) +
                ", at most 7680x4320 pixels in all");
  auto finite3 = [](const std::optional<std::array<double, 3>>& v, const char* what) {
    if (v && !(std::isfinite((*v)[0]) && std::isfinite((*v)[1]) && std::isfinite((*v)[2])))
      throw Error(std::string("render: camera ") + what + ": expected three finite numbers (metres)");
  };
  finite3(view.eye, "eye");
  finite3(view.target, "target");
  if (view.fovDeg && !(*view.fovDeg > 0 && *view.fovDeg < 180))
    throw Error("render: camera fov " + std::to_string(*view.fovDeg) +
                ": expected degrees between 0 and 180");
  if (view.eye && view.target && *view.eye == *view.target)
    throw Error("render: camera eye and target are the same point");
  if (!m->picture) m->picture = std::make_unique<Impl::Picture>();
  Impl::Picture& p = *m->picture;
  if (p.renderer.width() != width || p.renderer.height() != height) {
    std::string err;
    if (!p.renderer.init(width, height, err)) {
      m->picture.reset();
      throw Error("render: " + err);
    }
  }
  const World& w = *m->world;
  SceneLayout layout = sceneLayout(w);
  // The frame is chosen for the scene as first drawn; a module or body added since starts it again
  // (the start state must list what the layout lists).
  const bool same = p.started && layout.modules.size() == p.layout.modules.size() &&
                    layout.items.size() == p.layout.items.size();
  p.layout = std::move(layout);
  captureState(w, p.layout, p.now);
  if (!same) {
    p.start = p.now;
    p.started = true;
  }
  SceneLayout::CameraDef& cam = p.layout.camera;
  const SceneLayout::CameraDef kept = cam;
  auto vec = [](const std::array<double, 3>& a) { return Vec3(a[0], a[1], a[2]); };
  if (view.eye) cam.eye = vec(*view.eye);
  if (view.target) cam.target = vec(*view.target);
  if (view.fovDeg) cam.fovDeg = *view.fovDeg;
  const Camera camera = sceneCamera(p.layout, p.start, p.now);
  cam = kept;
  p.renderer.draw(buildSnapshot(p.layout, p.now), camera);
  const std::vector<uint8_t>& rgba = p.renderer.rgba();
  std::vector<uint8_t> rgb(size_t(width) * size_t(height) * 3);
  for (size_t i = 0, n = size_t(width) * size_t(height); i < n; ++i) {
    rgb[3 * i] = rgba[4 * i];
    rgb[3 * i + 1] = rgba[4 * i + 1];
    rgb[3 * i + 2] = rgba[4 * i + 2];
  }
  return rgb;
}

std::string Simulation::snapshot() const {
  m->check();
  if (!m->options.snapshots)
    throw Error("snapshot(): this world was made with snapshots=False (it keeps no inputs to re-run)");
  nlohmann::json h;
  h["world"] = m->path;
  h["source"] = m->source;
  h["name"] = m->name;
  h["root"] = m->root;
  h["seed"] = m->options.seed ? nlohmann::json(*m->options.seed) : nlohmann::json(nullptr);
  h["params"] = m->options.params;
  h["strict"] = m->options.strict;
  h["policy"] = m->options.policy;
  h["steps"] = m->world->steps();
  h["ended"] = m->ended;
  h["reads"] = m->reads;
  nlohmann::json texts = nlohmann::json::array();
  for (const auto& [p, t] : m->sources->taken()) texts.push_back({p, t});
  h["texts"] = texts;
  nlohmann::json acts = nlohmann::json::array();
  for (const Impl::Act& a : m->acts) acts.push_back({a.step, a.rows, a.stride, a.at});
  h["acts"] = acts;
  const std::string header = h.dump(-1, ' ', false, nlohmann::json::error_handler_t::strict);
  std::string body;
  put64(body, header.size());
  body += header;
  put64(body, m->actData.size());
  body.append(reinterpret_cast<const char*>(m->actData.data()), m->actData.size() * sizeof(double));
  uLongf packed = compressBound(uLong(body.size()));
  std::string out(kMagic, 8);
  put64(out, body.size());
  const size_t at = out.size();
  out.resize(at + packed);
  if (compress2(reinterpret_cast<Bytef*>(&out[at]), &packed, reinterpret_cast<const Bytef*>(body.data()),
                uLong(body.size()), 1) != Z_OK)
    throw Error("snapshot: compression failed");
  out.resize(at + packed);
  return out;
}

std::unique_ptr<Simulation> Simulation::fromSnapshot(const std::string& bytes, int threads,
                                                     const std::function<bool()>& interrupted) {
  return fromSnapshot(bytes, threads, interrupted, nullptr);
}

std::unique_ptr<Simulation> Simulation::fromSnapshot(const std::string& bytes, int threads,
                                                     const std::function<bool()>& interrupted,
                                                     std::shared_ptr<rm3d::MeshCache> meshes) {
  if (bytes.size() < 16 || bytes.compare(0, 8, kMagic, 8) != 0)
    throw Error("snapshot: not an RM3D snapshot (it does not start with " + std::string(kMagic, 8) + ")");
  size_t at = 8;
  const uint64_t rawSize = get64(bytes, at);
  // zlib expands at most about 1032 to 1: a larger size field is damage, not a reason to allocate.
  if (rawSize > (uint64_t(bytes.size() - at) + 64) * 1032)
    throw Error("snapshot: its size field is implausible (damaged bytes)");
  std::string body(size_t(rawSize), '\0');
  uLongf got = uLongf(rawSize);
  if (uncompress(reinterpret_cast<Bytef*>(body.data()), &got,
                 reinterpret_cast<const Bytef*>(bytes.data() + at), uLong(bytes.size() - at)) != Z_OK ||
      got != rawSize)
    throw Error("snapshot: the bytes are damaged (they do not unpack)");
  size_t p = 0;
  const uint64_t hlen = get64(body, p);
  if (hlen > body.size() - p) throw Error("snapshot: the bytes end early (truncated or not a snapshot)");
  nlohmann::json h = nlohmann::json::parse(body.substr(p, size_t(hlen)), nullptr, false);
  p += size_t(hlen);
  if (h.is_discarded() || !h.is_object()) throw Error("snapshot: its header is damaged");
  const uint64_t nAct = get64(body, p);
  if (nAct > (body.size() - p) / sizeof(double)) throw Error("snapshot: the bytes end early (truncated)");
  std::unique_ptr<Simulation> s(new Simulation());
  Impl& m = *s->m;
  m.meshes = std::move(meshes);
  try {
    m.options.threads = threads;
    if (!h.at("seed").is_null()) m.options.seed = h.at("seed").get<uint64_t>();
    m.options.params = h.at("params").get<std::map<std::string, std::string>>();
    m.options.strict = h.at("strict").get<bool>();
    m.options.policy = h.at("policy").get<bool>();
    m.path = h.at("world").get<std::string>();
    m.source = h.at("source").get<std::string>();
    m.name = h.at("name").get<std::string>();
    // The bytes are untrusted input: a root the header names is taken only where it is an RM3D
    // project, as World(root=) requires (a header saying root = "/" was accepted, and a mesh
    // outside the project loaded); else the root is found as for a new World of that file.
    const std::string root = h.at("root").get<std::string>();
    checkNoNul(m.path, "snapshot: its world path");
    checkNoNul(root, "snapshot: its root");
    if (!m.path.empty() && !fs::path(m.path).is_absolute())
      throw Error("snapshot: its world path '" + m.path + "' is not absolute (damaged bytes)");
    std::error_code ec;
    m.root = !root.empty() && fs::path(root).is_absolute() && isDataRoot(root)
                 ? fs::weakly_canonical(root, ec).string()
                 : findRoot(Options{}, m.path);
    m.actData.resize(size_t(nAct));
    // A snapshot taken before any action (a batch's start) has none: no copy from a null pointer.
    if (nAct > 0) std::memcpy(m.actData.data(), body.data() + p, size_t(nAct) * sizeof(double));
    for (const auto& a : h.at("acts")) {
      const Impl::Act act{a.at(0).get<int64_t>(), a.at(1).get<int>(), a.at(2).get<int>(),
                          a.at(3).get<size_t>()};
      if (act.rows < 0 || act.stride < 0 || act.at > m.actData.size() ||
          size_t(act.rows) * size_t(act.stride) > m.actData.size() - act.at)
        throw Error("snapshot: an action record lies outside the data (damaged bytes)");
      m.acts.push_back(act);
    }
    std::map<std::string, std::string> texts;
    for (const auto& t : h.at("texts")) texts[t.at(0).get<std::string>()] = t.at(1).get<std::string>();
    // What the re-run does not find among the texts comes from the disk. The world's own folder
    // counts only where the world file there is the one the bytes carry; otherwise a header could
    // name any folder and have a hook `require` from it. Then only the project root is read.
    m.sources = std::make_shared<SourceFiles>();
    std::string onDisk;
    const auto recorded = m.path.empty() ? texts.end() : texts.find(SourceFiles::key(m.path));
    const bool same = recorded != texts.end() &&
                      readTextFile(m.path, onDisk, nullptr, recorded->second.size()) &&
                      onDisk == recorded->second;
    if (!m.path.empty() && !same)
      m.sources->limitDisk({m.root}, " (this world came from a snapshot whose world file " + m.path +
                                         " is not here as it was: besides the snapshot's texts, only the "
                                         "project root " +
                                         m.root + " is read)");
    m.sources->setOverlay(std::move(texts));
    const int64_t steps = h.at("steps").get<int64_t>();
    const std::vector<int64_t> reads = h.at("reads").get<std::vector<int64_t>>();
    m.load();
    // Re-run: the reads and the actions at the steps they happened (see the top of this file).
    size_t r = 0, a = 0;
    World& w = *m.world;
    auto readsDue = [&] {
      while (r < reads.size() && reads[r] == w.steps()) {
        ++r;
        m.refresh();
      }
    };
    while (w.steps() < steps) {
      if (interrupted && w.steps() > 0 && w.steps() % 64 == 0 && interrupted())
        throw Error("snapshot: the re-run was interrupted at step " + std::to_string(w.steps()) + " of " +
                    std::to_string(steps));
      readsDue();
      while (a < m.acts.size() && m.acts[a].step < w.steps()) ++a;
      if (a < m.acts.size() && m.acts[a].step == w.steps())
        w.setActions(m.actData.data() + m.acts[a].at, m.acts[a].stride, m.acts[a].rows);
      w.step();
      if (w.stopped() && w.steps() < steps)
        throw Error("snapshot: the world stopped at step " + std::to_string(w.steps()) + " of " +
                    std::to_string(steps) + " on the re-run");
    }
    readsDue();
    m.sources->clearOverlay();
    if (h.at("ended").get<bool>()) {
      m.ended = true;
      std::string err;
      if (WorldScript* script = w.script();
          script && w.scriptError().empty() && !script->atEnd(w.time(), err))
        w.setScriptError(err);
    }
  } catch (const nlohmann::json::exception& e) {
    throw Error(std::string("snapshot: its header is damaged (") + e.what() + ")");
  } catch (const InputError& e) {
    throw Error(std::string("snapshot: ") + e.what());
  }
  return s;
}

void Simulation::restore(const std::string& bytes, const std::function<bool()>& interrupted) {
  m->check();
  std::unique_ptr<Simulation> other = fromSnapshot(bytes, m->options.threads, interrupted, m->meshes);
  std::shared_ptr<AgentArrays> target = m->target, kept = m->own;
  const int offset = m->rowOffset, limit = m->rowLimit;
  const bool bound = target != m->own;
  m->endRecording();
  std::swap(m, other->m);
  if (bound) {
    bindArrays(target, offset, limit);
    return;
  }
  // Views of the arrays held from before (a kept `w.act`) go on reading and driving this world:
  // the restored arrays are copied into the same buffers where their shapes agree.
  AgentArrays& now = *m->own;
  AgentArrays& k = *kept;
  if (k.rows != now.rows || k.obsDim != now.obsDim || k.actDim != now.actDim) return;
  std::copy(now.obs.begin(), now.obs.end(), k.obs.begin());
  std::copy(now.act.begin(), now.act.end(), k.act.begin());
  std::copy(now.reward.begin(), now.reward.end(), k.reward.begin());
  std::copy(now.done.begin(), now.done.end(), k.done.begin());
  std::copy(now.mask.begin(), now.mask.end(), k.mask.begin());
  std::copy(now.obsSize.begin(), now.obsSize.end(), k.obsSize.begin());
  std::copy(now.actSize.begin(), now.actSize.end(), k.actSize.begin());
  m->own = kept;
  m->target = kept;
}

std::unique_ptr<Simulation> Simulation::fork(const std::function<bool()>& interrupted) const {
  m->check();
  return fromSnapshot(snapshot(), m->options.threads, interrupted);
}

void Simulation::close() {
  if (m->closed) return;
  m->closed = true;
  m->endRecording();
}

bool Simulation::closed() const {
  return m->closed;
}

}  // namespace rm3d::api
