// `rm3d run`: one world, headless; prints a summary line, writes JSON and pictures.
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <thread>

#include "app/app.h"
#include "app/fork.h"
#include "app/html_replay.h"
#include "app/progress_line.h"
#include "app/run_identity.h"
#include "app/run_world.h"
#include "app/video_pipe.h"
#include "app/world_session.h"
#include "core/error.h"
#include "core/source_files.h"
#include "io/graph_export.h"
#include "io/run_capture.h"
#include "io/summary.h"
#include "io/trace_writer.h"
#include "io/world_snapshot.h"
#include "render/offscreen_renderer.h"
#include "script/world_script.h"

namespace fs = std::filesystem;

namespace rm3d {

bool parseParams(const std::vector<std::string>& in, std::map<std::string, std::string>& out,
                 std::string& err) {
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

/// `run --watch`: steps in real time and applies edits as they are saved (WorldSession): a
/// changed behaviour or lua/ file is reloaded into the running modules (state kept); a changed
/// world script rebuilds the world (a rejected one keeps the last good world running). Ends at
/// --seconds/--steps, world.stop(), or when interrupted.
int watchLoop(const RunArgs& a, const RunOptions& o) {
  WorldSession session(a.world, o);
  if (!session.load())
    std::fprintf(stderr, "rm3d: %s (fix it and save; watching)\n", session.worldError().c_str());
  auto start = WallClock::now();
  double simAtStart = 0;
  std::printf("watching %zu files; edit and save to reload (Ctrl-C to stop)\n", session.watchedCount());
  std::fflush(stdout);
  for (;;) {
    if (interruptSignal()) break;
    if (session.hasWorld()) {
      World& w = session.world();
      if (a.steps && w.steps() >= *a.steps) break;
      if (a.seconds && w.time() >= *a.seconds - 1e-9) break;
      if (w.stopped()) break;
      w.step();
      // Real time: the simulation never runs ahead of the clock.
      const double ahead =
          (w.time() - simAtStart) - std::chrono::duration<double>(WallClock::now() - start).count();
      if (ahead > 0) std::this_thread::sleep_for(std::chrono::duration<double>(ahead));
    } else {
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
    const SessionChanges c = session.poll();
    if (!c.worldError.empty())
      std::fprintf(stderr, "rm3d: %s (fix it and save; %s)\n", c.worldError.c_str(),
                   session.hasWorld() ? "the previous world keeps running" : "watching");
    if (c.rebuilt) {
      std::printf("world script changed: rebuilt %s (%zu modules)\n", a.world.c_str(),
                  session.world().modules().size());
      start = WallClock::now();
      simAtStart = 0;
    }
    for (const SessionChanges::Rejected& r : c.rejected)
      std::printf("reload rejected, old code keeps running: %s\n", r.error.c_str());
    for (const SessionChanges::Reload& r : c.reloaded)
      std::printf(
          "reloaded %s into %d modules at t=%.2f s (seen within 100 ms of saving; %.1f ms to reload)\n",
          r.file.c_str(), r.modules, session.world().time(), r.millis);
    if (!c.empty()) std::fflush(stdout);
  }
  const bool ok = session.hasWorld();
  if (ok) {
    World& w = session.world();
    if (w.script() && w.scriptError().empty()) {
      std::string err;
      if (!w.script()->atEnd(w.time(), err))
        std::fprintf(stderr, "rm3d: world script error: %s\n", err.c_str());
    }
    std::printf("%s: %lld steps, %.2f s simulated, %zu module%s, %d fault%s%s\n", a.world.c_str(),
                (long long)w.steps(), w.time(), w.modules().size(), w.modules().size() == 1 ? "" : "s",
                w.faultCount(), w.faultCount() == 1 ? "" : "s", interruptSignal() ? " (interrupted)" : "");
  }
  if (interruptSignal()) return 128 + interruptSignal();
  // The world file as last saved must load (the previous world may have run on meanwhile).
  return ok && session.worldError().empty() ? 0 : 2;
}

/// --record, --fork/--at and the camera flags: what can be checked before a run.
bool checkCaptureArgs(const RunArgs& a, const CameraArgs& camera, std::string& err) {
  SceneLayout::CameraDef probe;
  if (!applyCameraArgs(camera, probe, err)) return false;
  if (a.fork.empty() != !a.at.has_value()) {
    err = a.fork.empty() ? "--at T needs --fork FILE (the recording to fork from)"
                         : "--fork FILE needs --at T (the time to fork at, in simulated seconds)";
    return false;
  }
  if (!a.fork.empty() && (a.seed || !a.params.empty())) {
    err = "--fork re-simulates with the recorded seed and params; drop --seed and --param";
    return false;
  }
  if ((!a.fork.empty() || !a.record.empty() || !a.html.empty()) && a.watch) {
    err = std::string(!a.record.empty() ? "--record"
                      : !a.html.empty() ? "--html"
                                        : "--fork") +
          " cannot be combined with --watch";
    return false;
  }
  if (!a.fork.empty() && a.seconds && *a.seconds < *a.at) {
    err = "--seconds must reach the fork time --at";
    return false;
  }
  if (!a.record.empty() && !prepareOutputFile("--record", a.record, err)) return false;
  if (!a.html.empty() && (!prepareOutputFile("--html", a.html, err) || !htmlReplayReady(err))) {
    if (err.rfind("--html", 0) != 0) err = "--html " + a.html + ": " + err;
    return false;
  }
  if (!a.record.empty() && !a.fork.empty() && SourceFiles::key(a.record) == SourceFiles::key(a.fork)) {
    err = "--record " + a.record + ": is the recording --fork reads; write the new one elsewhere";
    return false;
  }
  return true;
}

/// --html: the page from the recording the run just wrote.
bool writeRunHtml(const std::string& record, const std::string& html, std::string& err) {
  Recording rec;
  if (!rec.load(record, err)) return false;
  HtmlReplayStats stats;
  if (!writeHtmlReplay(rec, rec.layout().camera, html, stats, err)) return false;
  std::printf("wrote %s (%.1f MiB, %lld of %lld frames)\n", html.c_str(), double(stats.bytes) / (1 << 20),
              (long long)stats.keptFrames, (long long)stats.recordedFrames);
  return true;
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
  if (a.seconds &&
      !(*a.seconds > 0 && *a.seconds <= 1e9)) {  // CLI11's PositiveNumber lets nan and 1e300 through
    std::fprintf(stderr, "rm3d run: --seconds %g: expected simulated seconds, more than 0 and at most 1e9\n",
                 *a.seconds);
    return 2;
  }
  if (a.seed) o.seed = *a.seed;
  o.strict = a.strict;
  o.threads = a.threads;
  o.chunkSize = a.chunk;
  o.echoLog = !a.quiet;
  o.watchdogSeconds = a.watchdog;
  if (!(a.memoryBudget >= 1 && a.memoryBudget <= 1048576)) {  // CLI11's Range lets nan through
    std::fprintf(stderr, "rm3d run: --memory-budget %g: expected MiB, 1 to 1048576\n", a.memoryBudget);
    return 2;
  }
  o.memoryBudget = a.memoryBudget * 1048576.0;
  if (!a.video.empty() && !onPath("ffmpeg")) {
    std::fprintf(stderr,
                 "rm3d run: --video needs ffmpeg, which is not installed (apt-get install ffmpeg); --png and "
                 "--frames work without it\n");
    return 2;
  }
  // Output paths are checked (and their folders made) before a long run, not after it.
  if (!checkOutputsApart({{"the world script", a.world}, {"--fork", a.fork}},
                         {{"--json", a.json},
                          {"--png", a.png},
                          {"--graph", a.graph},
                          {"--video", a.video},
                          {"--trace", a.trace},
                          {"--record", a.record},
                          {"--html", a.html}},
                         err)) {
    std::fprintf(stderr, "rm3d run: %s\n", err.c_str());
    return 2;
  }
  if (!a.frames.empty() && !prepareOutputFolder("--frames", a.frames, err)) {
    std::fprintf(stderr, "rm3d run: %s\n", err.c_str());
    return 2;
  }
  for (const auto& [flag, path] : {std::pair{"--json", a.json}, std::pair{"--png", a.png},
                                   std::pair{"--graph", a.graph}, std::pair{"--video", a.video}}) {
    if (!path.empty() && !prepareOutputFile(flag, path, err)) {
      std::fprintf(stderr, "rm3d run: %s\n", err.c_str());
      return 2;
    }
  }
  // --trace: rows go to FILE.part while the run lasts (io/trace_writer.h).
  TraceWriter trace;
  if (a.traceEvery > 0 && a.trace.empty()) {
    std::fprintf(stderr, "rm3d run: --trace-every %d needs --trace FILE.csv\n", a.traceEvery);
    return 2;
  }
  if (!a.trace.empty() && a.watch) {
    std::fprintf(stderr,
                 "rm3d run: --trace does not work with --watch (a rebuilt world starts its clock again)\n");
    return 2;
  }
  if (!a.trace.empty() &&
      (!prepareOutputFile("--trace", a.trace, err) || !trace.open(a.trace, a.traceEvery, err))) {
    std::fprintf(stderr, "rm3d run: %s\n", err.c_str());
    return 2;
  }
  int width = 1280, height = 720;
  if (!a.size.empty() && (std::sscanf(a.size.c_str(), "%dx%d", &width, &height) != 2 || width < 16 ||
                          height < 16 || width > 8192 || height > 8192)) {
    std::fprintf(stderr, "rm3d run: --size %s: expected WIDTHxHEIGHT, e.g. 1280x720\n", a.size.c_str());
    return 2;
  }
  // Record, fork, camera (io/run_capture.h, app/fork.h): checked before the run.
  const CameraArgs cameraArgs{a.eye, a.target, a.fov};
  if (!checkCaptureArgs(a, cameraArgs, err)) {
    std::fprintf(stderr, "rm3d run: %s\n", err.c_str());
    return 2;
  }
  ForkPlan fork;
  if (!a.fork.empty() && !prepareFork(a.fork, *a.at, a.world, o, fork, err)) {
    std::fprintf(stderr, "rm3d run: %s\n", err.c_str());
    return 2;
  }
  // --html without --record records into a file beside the page, read back and removed at the end.
  const std::string record = !a.record.empty() || a.html.empty() ? a.record : a.html + ".rm3drec.part";
  if (!record.empty() && !o.sources) o.sources = std::make_shared<SourceFiles>();
  RecordingMeta meta{SourceFiles::key(a.world),
                     SourceFiles::key(root),
                     a.seed.value_or(1),
                     a.seed.has_value(),
                     o.params,
                     0,
                     a.commandLine,
                     ""};
  RunCapture capture(record, meta, cameraArgs);
  capture.setLabels(a.labels);
  const bool capturing = !record.empty() || !a.frames.empty() || !a.video.empty();
  bool forkMatched = true;
  auto forkIfDue = [&](World& w) {
    if (a.fork.empty() || fork.done || w.steps() < fork.step) return;
    std::vector<std::string> report;
    forkMatched = forkNow(w, fork, report);
    for (const std::string& line : report) std::printf("%s\n", line.c_str());
    std::fflush(stdout);
  };
  const StepHook onStart = [&](World& w) {
    capture.start(w);
    if (!capture.error().empty()) std::fprintf(stderr, "rm3d run: %s\n", capture.error().c_str());
    forkIfDue(w);
  };
  installInterruptHandlers();
  if (a.watch) return watchLoop(a, o);
  // Pictures while running: PNG frames and/or a video piped to ffmpeg, every `every` steps.
  std::unique_ptr<OffscreenRenderer> renderer;
  VideoPipe video;
  std::string videoError;  // the first problem with the video; the run goes on without it
  long long frameNo = 0, videoFrames = 0;
  std::string framesError;
  StepHook onStep;
  if (!a.frames.empty() || !a.video.empty()) {
    renderer = std::make_unique<OffscreenRenderer>();
    std::string perr;
    if (!renderer->init(width, height, perr)) {
      std::fprintf(stderr, "rm3d run: %s\n", perr.c_str());
      return 2;
    }
    onStep = [&, every = a.every](World& w) {
      capture.step(w);
      forkIfDue(w);
      const int n = every > 0 ? every : std::max(1, int(std::lround(1.0 / (30.0 * w.settings().dt))));
      if (w.steps() % n != 0) return;
      if (!a.video.empty() && !video.isOpen() && videoError.empty()) {
        const double fps = 1.0 / (n * w.settings().dt);
        if (!video.open(a.video, width, height, fps, videoError))
          std::fprintf(stderr, "rm3d run: %s\n", videoError.c_str());
      }
      renderer->draw(capture.snapshot(), capture.camera());
      if (video.isOpen() && !video.failed()) {
        if (video.write(renderer->rgba().data(), renderer->rgba().size()))
          ++videoFrames;
        else
          std::fprintf(stderr,
                       "rm3d run: --video %s: ffmpeg stopped taking frames at t=%.3f s; the run goes on "
                       "without the video\n",
                       a.video.c_str(), w.time());
      }
      if (!a.frames.empty()) {
        char name[64];
        std::snprintf(name, sizeof name, "frame_%06lld.png", frameNo);
        std::string perr;
        if (!renderer->writePng((fs::path(a.frames) / name).string(), perr) && framesError.empty()) {
          framesError = perr;
          std::fprintf(stderr, "rm3d run: --frames: %s\n", perr.c_str());
        }
      }
      ++frameNo;
    };
  }
  if (!onStep && capturing)
    onStep = [&](World& w) {
      capture.step(w);
      forkIfDue(w);
    };
  else if (!onStep && !a.fork.empty())
    onStep = forkIfDue;
  // The end time the progress line counts towards: --seconds, --steps or the world's duration.
  std::unique_ptr<ProgressLine> progress;
  const StepHook everyStep = [&](World& w) {
    if (trace.isOpen()) trace.sample(w);
    if (onStep) onStep(w);
    if (!progress)
      progress = std::make_unique<ProgressLine>(a.seconds ? *a.seconds
                                                : a.steps ? double(*a.steps) * w.settings().dt
                                                          : w.settings().duration);
    progress->update(w);
  };
  const StepHook atStart = [&](World& w) {
    onStart(w);
    if (trace.isOpen()) trace.sample(w);
  };
  WorldRun r = runWorldFile(a.world, o, a.steps, a.seconds, everyStep, atStart);
  progress.reset();  // erases the line
  int code = r.exitCode;
  std::vector<std::string> outputErrors;
  if (trace.isOpen() && !r.loadError.empty()) trace.discard();
  if (trace.isOpen()) {
    std::string terr;
    if (trace.finish(*r.world, terr)) {
      std::printf("wrote %lld rows x %zu columns to %s\n", (long long)trace.rows(), trace.columns(),
                  a.trace.c_str());
    } else {
      std::fprintf(stderr, "rm3d run: %s\n", terr.c_str());
      outputErrors.push_back(terr);
    }
  }
  if (video.isOpen() && !video.close(videoError))
    std::fprintf(stderr, "rm3d run: %s\n", videoError.c_str());
  else if (video.isOpen() || videoFrames > 0)
    std::printf("wrote %lld frames to %s\n", videoFrames, a.video.c_str());
  if (!videoError.empty()) outputErrors.push_back(videoError);
  if (!record.empty() && capture.started()) {
    std::string rerr;
    if (!capture.finish(o.sources->taken(), rerr)) {
      std::fprintf(stderr, "rm3d run: %s\n", rerr.c_str());
      outputErrors.push_back(rerr);
    } else if (std::string herr; !a.html.empty() && !writeRunHtml(record, a.html, herr)) {
      std::fprintf(stderr, "rm3d run: %s\n", herr.c_str());
      outputErrors.push_back(herr);
    }
    if (a.record.empty()) {
      std::error_code ec;
      fs::remove(record, ec);
    } else if (rerr.empty()) {
      const double frames = double(std::max<int64_t>(1, capture.writer().frames()));
      std::printf("wrote %lld frames (%.1f KiB, %.2f KiB and %.3f ms per step) to %s (the recording)\n",
                  (long long)capture.writer().frames(), double(capture.writer().bytes()) / 1024,
                  double(capture.writer().bytes()) / 1024 / frames, capture.recordSeconds() * 1000 / frames,
                  a.record.c_str());
    }
  }
  if (!a.fork.empty() && r.loadError.empty() && !fork.done)
    std::fprintf(stderr, "rm3d run: --at %g: the run ended at t=%.4f s, before the fork\n", *a.at,
                 r.world->time());
  if (!forkMatched)
    std::fprintf(stderr, "rm3d run: warning: the re-simulation differs from the recording at the fork\n");
  if (!framesError.empty())
    outputErrors.push_back("--frames: " + framesError);
  else if (!a.frames.empty() && frameNo > 0)
    std::printf("wrote %lld frames to %s\n", frameNo, a.frames.c_str());
  World& w = *r.world;
  if (!r.loadError.empty()) std::fprintf(stderr, "rm3d: %s\n", r.loadError.c_str());
  if (!r.runError.empty()) std::fprintf(stderr, "rm3d: %s\n", r.runError.c_str());
  if (!w.scriptError().empty())
    std::fprintf(stderr, "rm3d: world script error: %s\n", w.scriptError().c_str());
  if (!w.divergence().empty()) std::fprintf(stderr, "rm3d: %s\n", w.divergence().c_str());
  for (const Failure& f : w.failures())
    std::fprintf(stderr, "FAILED at t=%.3f: %s\n", f.time, f.message.c_str());
  // The fault that ended a --strict run (with the log echoed, it was printed when it happened).
  if (w.fatalFault() && !o.echoLog)
    for (const Module& m : w.modules())
      if (!m.fault.empty())
        std::fprintf(stderr, "rm3d: --strict: module %s faulted: %s\n", m.name.c_str(), m.fault.c_str());
  for (const std::string& u : r.unrunChecks) std::fprintf(stderr, "rm3d: warning: %s\n", u.c_str());
  if (code == kExitWatchdog)
    std::fprintf(
        stderr,
        "rm3d: the watchdog stopped a call that did not return within %g s (--watchdog); exit code %d\n",
        o.watchdogSeconds, int(kExitWatchdog));
  if (r.signal)
    std::fprintf(stderr, "rm3d: interrupted (%s) at t=%.3f s after %lld steps; summary written as usual\n",
                 signalName(r.signal), w.time(), (long long)w.steps());
  if (r.loadError.empty()) {
    const double rtf = r.wallSeconds > 0 ? w.time() / r.wallSeconds : 0;
    std::printf(
        "%s: %lld steps, %.2f s simulated in %.2f s (%.1fx real time), %zu module%s, %d fault%s, %zu failed "
        "expectation%s\n",
        a.world.c_str(), (long long)w.steps(), w.time(), r.wallSeconds, rtf, w.modules().size(),
        w.modules().size() == 1 ? "" : "s", w.faultCount(), w.faultCount() == 1 ? "" : "s",
        w.failures().size(), w.failures().size() == 1 ? "" : "s");
  }
  if (!a.graph.empty() && r.loadError.empty()) {
    const bool dot = fs::path(a.graph).extension() == ".dot" || fs::path(a.graph).extension() == ".gv";
    std::ofstream f(a.graph);
    f << (dot ? graphDot(w) : graphJson(w) + "\n");
    f.close();
    if (!f) {
      std::fprintf(stderr, "rm3d run: --graph %s: cannot write the file\n", a.graph.c_str());
      outputErrors.push_back("--graph " + a.graph + ": cannot write the file");
    } else {
      std::printf("wrote %s (the connection graph)\n", a.graph.c_str());
    }
  }
  if (!a.png.empty() && r.loadError.empty()) {
    OffscreenRenderer renderer;
    std::string perr;
    if (!renderer.init(width, height, perr)) {
      std::fprintf(stderr, "rm3d run: --png: %s\n", perr.c_str());
      outputErrors.push_back("--png: " + perr);
    } else {
      if (capture.started()) capture.refresh(w);
      if (capture.started())
        renderer.draw(capture.snapshot(), capture.camera());
      else
        renderer.draw(buildSnapshot(w), worldCamera(w));
      if (!renderer.writePng(a.png, perr)) {
        std::fprintf(stderr, "rm3d run: --png: %s\n", perr.c_str());
        outputErrors.push_back("--png: " + perr);
      } else {
        std::printf("wrote %s (the last frame, %dx%d)\n", a.png.c_str(), width, height);
      }
    }
  }
  // The summary last, so it lists every output that failed.
  if (!a.json.empty()) {
    nlohmann::json j =
        r.loadError.empty() ? runSummary(w, r.wallSeconds) : nlohmann::json{{"error", r.loadError}};
    if (!r.runError.empty()) j["error"] = r.runError;
    addRunIdentity(j, a.commandLine, o.params);
    j["interrupted"] = r.signal != 0;
    if (r.signal) {
      j["signal"] = signalName(r.signal);
      j["stop_time"] = w.time();
    }
    j["warnings"] = r.unrunChecks;
    j["output_errors"] = outputErrors;
    j["exit_code"] = std::max(code, outputErrors.empty() ? 0 : int(kExitBadInput));
    std::ofstream f(a.json);
    f << j.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) << "\n";
    f.close();
    if (!f) {
      std::fprintf(stderr, "rm3d run: --json %s: cannot write the file\n", a.json.c_str());
      outputErrors.push_back("--json " + a.json + ": cannot write the file");
    } else {
      std::printf("wrote %s (the run's summary)\n", a.json.c_str());
    }
  }
  // An output that could not be written is exit code 2; an interrupt (130, 143) outranks it.
  if (!outputErrors.empty()) code = std::max(code, int(kExitBadInput));
  return code;
}

}  // namespace rm3d
