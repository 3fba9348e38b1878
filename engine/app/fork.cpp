#include "app/fork.h"

#include <cmath>
#include <cstring>
#include <filesystem>

#include "core/source_files.h"
#include "core/text_file.h"
#include "io/scene_state.h"

namespace fs = std::filesystem;

namespace rm3d {

namespace {

/// `path` under `from` becomes the same relative path under `to`; else empty.
std::string rebase(const fs::path& path, const fs::path& from, const fs::path& to) {
  if (from.empty()) return {};
  const fs::path rel = path.lexically_relative(from);
  if (rel.empty() || rel.native().rfind("..", 0) == 0) return {};
  return (to / rel).lexically_normal().string();
}

bool samePose(const Pose& a, const Pose& b) {
  return std::memcmp(a.pos.data(), b.pos.data(), sizeof(double) * 3) == 0 &&
         std::memcmp(a.rot.coeffs().data(), b.rot.coeffs().data(), sizeof(double) * 4) == 0;
}

}  // namespace

bool prepareFork(const std::string& file, double at, const std::string& world, RunOptions& o, ForkPlan& plan,
                 std::string& err) {
  if (!plan.recording.load(file, err)) {
    err = "--fork " + err;
    return false;
  }
  const Recording& rec = plan.recording;
  if (rec.sources().empty() || rec.meta().worldFile.empty()) {
    err = "--fork " + file + ": the recording holds no sources to re-simulate with";
    return false;
  }
  const double end = double(rec.frameCount() - 1) * rec.layout().dt;
  if (!(at >= 0) || at > end + 1e-9) {
    char buf[200];
    std::snprintf(buf, sizeof buf, "--at %g: expected a time from 0 to %.4g s (where %s ends)", at, end,
                  file.c_str());
    err = buf;
    return false;
  }
  plan.at = at;
  plan.step = rec.frameAt(at);
  // Every frame is decoded now (in order: each from the one before): a damaged recording is bad
  // input (exit 2) before the run, not a "re-simulation differs" warning after it.
  SceneState probe;
  for (int64_t i = 0; i < rec.frameCount(); ++i)
    if (!rec.frame(i, probe, nullptr, err)) {
      err = "--fork " + err;
      return false;
    }
  plan.worldFile = SourceFiles::key(world);
  const fs::path oldWorld(rec.meta().worldFile), oldRoot(rec.meta().projectRoot);
  const fs::path newDir = fs::path(plan.worldFile).parent_path(), newRoot = SourceFiles::key(o.projectRoot);
  for (const auto& [path, text] : rec.sources()) {
    std::string now;
    if (path == rec.meta().worldFile) now = plan.worldFile;
    if (now.empty()) now = rebase(path, oldWorld.parent_path(), newDir);
    if (now.empty()) now = rebase(path, oldRoot, newRoot);
    if (now.empty()) now = path;
    plan.recorded.emplace(now, text);
  }
  if (!plan.recorded.count(plan.worldFile)) {
    err = "--fork " + file + ": the recording does not hold its world script";
    return false;
  }
  o.sources = std::make_shared<SourceFiles>();
  o.sources->setOverlay(plan.recorded);
  o.params = rec.meta().params;
  if (rec.meta().seedGiven) o.seed = rec.meta().seed;
  return true;
}

bool forkNow(World& w, ForkPlan& plan, std::vector<std::string>& report) {
  plan.done = true;
  char line[400];
  // The state here must be the recorded one, bit for bit (the run is deterministic).
  bool same = true;
  SceneState recorded, now;
  std::string err;
  const SceneLayout layout = sceneLayout(w);
  if (!plan.recording.frame(plan.step, recorded, nullptr, err)) {
    report.push_back(err);
    same = false;
  } else if (layout.modules.size() != plan.recording.layout().modules.size() ||
             layout.linkCount != plan.recording.layout().linkCount) {
    report.push_back("fork: the re-simulated world has other modules than the recording");
    same = false;
  } else {
    captureState(w, layout, now);
    size_t differ = 0;
    for (size_t i = 0; i < now.links.size(); ++i) differ += !samePose(now.links[i], recorded.links[i]);
    for (size_t i = 0; i < now.joints.size(); ++i)
      differ += std::memcmp(&now.joints[i], &recorded.joints[i], sizeof(double)) != 0;
    same = differ == 0 && now.docks == recorded.docks && now.steps == recorded.steps;
    std::snprintf(
        line, sizeof line,
        same ? "fork: re-simulated %lld steps to t=%.4f s with the recorded sources; the state matches "
               "the recording bit for bit"
             : "fork: re-simulated %lld steps to t=%.4f s, but %zu link poses or joint angles differ "
               "from the recording (a run that is not deterministic?)",
        (long long)w.steps(), w.time(), differ);
    report.push_back(line);
  }
  // From here on, the files as they are now.
  if (w.options().sources) w.options().sources->clearOverlay();
  std::string disk;
  if (readTextFile(plan.worldFile, disk) && disk != plan.recorded[plan.worldFile])
    report.push_back("fork: " + plan.worldFile +
                     " differs from the recorded world script; the recorded one runs on (the world keeps its "
                     "state; only behaviours and lua/ files reload)");
  for (const std::string& file : w.watchedFiles()) {
    if (file == plan.worldFile || file == w.worldFile()) continue;
    auto it = plan.recorded.find(file);
    // Only what the recorded run read and what changed since (a library file nobody read stays out).
    if (it == plan.recorded.end() || !readTextFile(file, disk) || it->second == disk) continue;
    std::vector<std::string> errors;
    const int n = w.reloadFile(file, errors);
    for (const std::string& e : errors)
      report.push_back("fork: reload rejected, the recorded code runs on: " + e);
    if (n > 0) {
      std::snprintf(line, sizeof line, "fork: reloaded %s into %d modules at t=%.4f s", file.c_str(), n,
                    w.time());
      report.push_back(line);
    }
  }
  return same;
}

}  // namespace rm3d
