// `rm3d run`: one world, headless; prints a summary line, writes JSON and pictures.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include <nlohmann/json.hpp>

#include "app/app.h"
#include "app/run_world.h"
#include "core/error.h"
#include "render/offscreen_renderer.h"
#include "world/world_snapshot.h"

namespace fs = std::filesystem;

namespace rm3d {

bool parseParams(const std::vector<std::string>& in, std::map<std::string, std::string>& out, std::string& err) {
  for (const std::string& p : in) {
    const size_t eq = p.find('=');
    if (eq == std::string::npos || eq == 0) {
      err = "--param '" + p + "': expected key=value";
      return false;
    }
    out[p.substr(0, eq)] = p.substr(eq + 1);
  }
  return true;
}

WorldRun runWorldFile(const std::string& file, const RunOptions& options, std::optional<long long> steps,
                      std::optional<double> seconds) {
  WorldRun r;
  const auto t0 = std::chrono::steady_clock::now();
  r.world = std::make_unique<World>(options);
  World& w = *r.world;
  std::error_code ec;
  if (!fs::is_regular_file(file, ec)) {
    r.loadError = file + ": cannot read world file (" + (fs::exists(file, ec) ? "not a regular file" : "no such file") + ")";
    r.exitCode = 2;
    return r;
  }
  try {
    w.loadFile(file);
  } catch (const InputError& e) {
    r.loadError = e.what();
    r.exitCode = 2;
    return r;
  }
  long long limit = -1;
  if (steps) limit = *steps;
  if (seconds) limit = std::llround(*seconds / w.settings().dt);
  while (limit >= 0 ? (w.steps() < limit && !w.stopped()) : !w.finished()) w.step();
  r.wallSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (!w.scriptError().empty()) r.exitCode = 2;
  else if (!w.failures().empty() || w.fatalFault()) r.exitCode = 1;
  return r;
}

int runCommand(const RunArgs& a, const std::string& root) {
  RunOptions o;
  o.projectRoot = root;
  std::string err;
  if (!parseParams(a.params, o.params, err)) {
    std::fprintf(stderr, "rm3d run: %s\n", err.c_str());
    return 2;
  }
  if (a.seed) o.seed = *a.seed;
  o.strict = a.strict;
  o.threads = a.threads;
  o.echoLog = !a.quiet;
  if (!a.video.empty()) {
    std::fprintf(stderr, "rm3d run: --video is not in this build yet; use --png FILE for a picture of the last frame\n");
    return 2;
  }
  // Check output paths before a long run, not after it.
  for (const auto& [flag, path] : {std::pair{"--json", a.json}, std::pair{"--png", a.png}, std::pair{"--graph", a.graph}}) {
    if (path.empty()) continue;
    const fs::path dir = fs::absolute(path).parent_path();
    if (!fs::is_directory(dir)) {
      std::fprintf(stderr, "rm3d run: %s %s: folder %s does not exist\n", flag, path.c_str(), dir.string().c_str());
      return 2;
    }
  }
  int width = 1280, height = 720;
  if (!a.size.empty() && (std::sscanf(a.size.c_str(), "%dx%d", &width, &height) != 2 || width < 16 || height < 16 ||
                          width > 8192 || height > 8192)) {
    std::fprintf(stderr, "rm3d run: --size %s: expected WIDTHxHEIGHT, e.g. 1280x720\n", a.size.c_str());
    return 2;
  }
  WorldRun r = runWorldFile(a.world, o, a.steps, a.seconds);
  World& w = *r.world;
  if (!r.loadError.empty()) std::fprintf(stderr, "rm3d: %s\n", r.loadError.c_str());
  if (!w.scriptError().empty()) std::fprintf(stderr, "rm3d: world script error: %s\n", w.scriptError().c_str());
  for (const Failure& f : w.failures()) std::fprintf(stderr, "FAILED at t=%.3f: %s\n", f.time, f.message.c_str());
  if (r.loadError.empty()) {
    const double rtf = r.wallSeconds > 0 ? w.time() / r.wallSeconds : 0;
    std::printf("%s: %lld steps, %.2f s simulated in %.2f s (%.1fx real time), %zu modules, %d faults, %zu failed expectations\n",
                a.world.c_str(), (long long)w.steps(), w.time(), r.wallSeconds, rtf, w.modules().size(), w.faultCount(),
                w.failures().size());
  }
  if (!a.json.empty()) {
    std::ofstream f(a.json);
    nlohmann::json j = r.loadError.empty() ? w.summary(r.wallSeconds) : nlohmann::json{{"error", r.loadError}};
    f << j.dump(2) << "\n";
    if (!f) {
      std::fprintf(stderr, "rm3d run: cannot write %s\n", a.json.c_str());
      return 2;
    }
  }
  if (!a.graph.empty() && r.loadError.empty()) {
    const bool dot = fs::path(a.graph).extension() == ".dot" || fs::path(a.graph).extension() == ".gv";
    std::ofstream f(a.graph);
    f << (dot ? w.graphDot() : w.graphJson() + "\n");
    if (!f) {
      std::fprintf(stderr, "rm3d run: cannot write %s\n", a.graph.c_str());
      return 2;
    }
  }
  if (!a.png.empty() && r.loadError.empty()) {
    OffscreenRenderer renderer;
    std::string perr;
    if (!renderer.init(width, height, perr)) {
      std::fprintf(stderr, "rm3d run: --png: %s\n", perr.c_str());
      return 2;
    }
    renderer.draw(buildSnapshot(w), worldCamera(w));
    if (!renderer.writePng(a.png, perr)) {
      std::fprintf(stderr, "rm3d run: %s\n", perr.c_str());
      return 2;
    }
  }
  return r.exitCode;
}

}  // namespace rm3d
