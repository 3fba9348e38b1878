// `rm3d run`: one world, headless; prints a summary line, writes JSON and pictures.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <unistd.h>
#include <map>
#include <thread>

#include <nlohmann/json.hpp>

#include "app/app.h"
#include "app/file_watcher.h"
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
                      std::optional<double> seconds, const StepHook& onStep) {
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
  while (limit >= 0 ? (w.steps() < limit && !w.stopped()) : !w.finished()) {
    w.step();
    if (onStep) onStep(w);
  }
  r.wallSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (!w.scriptError().empty()) r.exitCode = 2;
  else if (!w.failures().empty() || w.fatalFault()) r.exitCode = 1;
  return r;
}

namespace {

using WallClock = std::chrono::steady_clock;

bool onPath(const char* program) {
  const char* path = std::getenv("PATH");
  if (!path) return false;
  std::string dirs = path;
  size_t start = 0;
  while (start <= dirs.size()) {
    const size_t end = dirs.find(':', start);
    const std::string dir = dirs.substr(start, end == std::string::npos ? std::string::npos : end - start);
    if (!dir.empty() && ::access((fs::path(dir) / program).c_str(), X_OK) == 0) return true;
    if (end == std::string::npos) break;
    start = end + 1;
  }
  return false;
}

/// `run --watch`: steps in real time and applies edits as they are saved: a changed behaviour or
/// lua/ file is reloaded into the running modules (state kept); a changed world script rebuilds
/// the world. Ends at --seconds/--steps, world.stop(), or when interrupted.
int watchLoop(const RunArgs& a, const RunOptions& o) {
  auto load = [&](std::unique_ptr<World>& w) {
    w = std::make_unique<World>(o);
    try {
      w->loadFile(a.world);
      return true;
    } catch (const InputError& e) {
      std::fprintf(stderr, "rm3d: %s (fix it and save; watching)\n", e.what());
      return false;
    }
  };
  std::unique_ptr<World> w;
  bool ok = load(w);
  FileWatcher watcher;
  auto snapshot = [&] {
    watcher.reset(ok ? w->watchedFiles() : std::vector<std::string>{fs::absolute(a.world).string()});
  };
  snapshot();
  auto start = WallClock::now();
  auto lastCheck = start;
  double simAtStart = 0;
  std::printf("watching %zu files; edit and save to reload (Ctrl-C to stop)\n", watcher.size());
  std::fflush(stdout);
  for (;;) {
    if (ok) {
      if (a.steps && w->steps() >= *a.steps) break;
      if (a.seconds && w->time() >= *a.seconds - 1e-9) break;
      if (w->stopped()) break;
      w->step();
      // Real time: the simulation never runs ahead of the clock.
      const double ahead = (w->time() - simAtStart) - std::chrono::duration<double>(WallClock::now() - start).count();
      if (ahead > 0) std::this_thread::sleep_for(std::chrono::duration<double>(ahead));
    } else {
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
    if (WallClock::now() - lastCheck < std::chrono::milliseconds(100)) continue;
    lastCheck = WallClock::now();
    for (const std::string& file : watcher.changed()) {
      const auto t0 = WallClock::now();
      if (!ok || file == w->worldFile()) {
        ok = load(w);
        if (ok) std::printf("world script changed: rebuilt %s (%zu modules)\n", a.world.c_str(), w->modules().size());
        start = WallClock::now();
        simAtStart = 0;
        snapshot();
        break;
      }
      std::vector<std::string> errors;
      const int n = w->reloadFile(file, errors);
      const double took = std::chrono::duration<double, std::milli>(WallClock::now() - t0).count();
      for (const std::string& e : errors) std::printf("reload rejected, old code keeps running: %s\n", e.c_str());
      if (n > 0)
        std::printf("reloaded %s into %d modules at t=%.2f s (seen within 100 ms of saving; %.1f ms to reload)\n",
                    file.c_str(), n, w->time(), took);
      std::fflush(stdout);
    }
  }
  if (ok)
    std::printf("%s: %lld steps, %.2f s simulated, %zu modules, %d faults\n", a.world.c_str(), (long long)w->steps(), w->time(),
                w->modules().size(), w->faultCount());
  return ok ? 0 : 2;
}

}  // namespace

int runCommand(const RunArgs& a, const std::string& root) {
  RunOptions o;
  o.projectRoot = root;
  std::string err;
  if (!parseParams(a.params, o.params, err)) {
    std::fprintf(stderr, "rm3d run: %s\n", err.c_str());
    return 2;
  }
  if (a.seconds && !(*a.seconds > 0 && *a.seconds <= 1e9)) {  // CLI11's PositiveNumber lets nan and 1e300 through
    std::fprintf(stderr, "rm3d run: --seconds %g: expected simulated seconds, more than 0 and at most 1e9\n", *a.seconds);
    return 2;
  }
  if (a.seed) o.seed = *a.seed;
  o.strict = a.strict;
  o.threads = a.threads;
  o.echoLog = !a.quiet;
  if (!a.video.empty() && !onPath("ffmpeg")) {
    std::fprintf(stderr, "rm3d run: --video needs ffmpeg, which is not installed (apt-get install ffmpeg); --png and --frames work without it\n");
    return 2;
  }
  if (!a.frames.empty()) {
    std::error_code ec;
    fs::create_directories(a.frames, ec);
    if (!fs::is_directory(a.frames)) {
      std::fprintf(stderr, "rm3d run: --frames %s: cannot create the folder\n", a.frames.c_str());
      return 2;
    }
  }
  // Check output paths before a long run, not after it.
  for (const auto& [flag, path] : {std::pair{"--json", a.json}, std::pair{"--png", a.png}, std::pair{"--graph", a.graph},
                                   std::pair{"--video", a.video}}) {
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
  if (a.watch) return watchLoop(a, o);
  // Pictures while running: PNG frames and/or a video piped to ffmpeg, every `every` steps.
  std::unique_ptr<OffscreenRenderer> renderer;
  FILE* video = nullptr;
  long long frameNo = 0;
  StepHook onStep;
  if (!a.frames.empty() || !a.video.empty()) {
    renderer = std::make_unique<OffscreenRenderer>();
    std::string perr;
    if (!renderer->init(width, height, perr)) {
      std::fprintf(stderr, "rm3d run: %s\n", perr.c_str());
      return 2;
    }
    onStep = [&, every = a.every](World& w) {
      const int n = every > 0 ? every : std::max(1, int(std::lround(1.0 / (30.0 * w.settings().dt))));
      if (w.steps() % n != 0) return;
      if (!video && !a.video.empty()) {
        const double fps = 1.0 / (n * w.settings().dt);
        char cmd[1024];
        std::snprintf(cmd, sizeof cmd,
                      "ffmpeg -y -loglevel error -f rawvideo -pix_fmt rgba -s %dx%d -r %.3f -i - -pix_fmt yuv420p "
                      "-vcodec libx264 -crf 23 '%s'", width, height, fps, a.video.c_str());
        video = popen(cmd, "w");
      }
      renderer->draw(buildSnapshot(w), worldCamera(w));
      if (video) std::fwrite(renderer->rgba().data(), 1, renderer->rgba().size(), video);
      if (!a.frames.empty()) {
        char name[64];
        std::snprintf(name, sizeof name, "frame_%06lld.png", frameNo);
        std::string err;
        renderer->writePng((fs::path(a.frames) / name).string(), err);
      }
      ++frameNo;
    };
  }
  WorldRun r = runWorldFile(a.world, o, a.steps, a.seconds, onStep);
  if (video && pclose(video) != 0) {
    std::fprintf(stderr, "rm3d run: ffmpeg failed writing %s\n", a.video.c_str());
    return 2;
  }
  if (video) std::printf("wrote %lld frames to %s\n", frameNo, a.video.c_str());
  World& w = *r.world;
  if (!r.loadError.empty()) std::fprintf(stderr, "rm3d: %s\n", r.loadError.c_str());
  if (!w.scriptError().empty()) std::fprintf(stderr, "rm3d: world script error: %s\n", w.scriptError().c_str());
  if (!w.divergence().empty()) std::fprintf(stderr, "rm3d: %s\n", w.divergence().c_str());
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
