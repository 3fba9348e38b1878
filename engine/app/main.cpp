// rm3d: entry point. Parses the command line (CLI11) and dispatches to the commands.
#include <CLI/CLI.hpp>
#include <cerrno>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <functional>
#include <string>

#include "app/app.h"
#include "app/bench_scenes.h"
#include "app/cmd_view.h"
#include "app/data_root.h"
#include "app/sweep.h"
#include "core/path_rule.h"
#include "core/version.h"

namespace {

/// A CLI11 check on a number whose message says what was expected: the parse error reads
/// "--steps must be a positive whole number of steps, got 0". `ok` sees the parsed value; `whole`
/// also requires an integer. (CLI11's own range checks print their bounds as 300-digit numbers.)
CLI::Validator numberCheck(std::string expected, std::function<bool(double)> ok, bool whole = false) {
  return CLI::Validator(
      [expected, ok, whole](std::string& in) -> std::string {
        const char* begin = in.c_str();
        char* end = nullptr;
        errno = 0;
        const double v = std::strtod(begin, &end);
        const bool number = end != begin && *end == '\0' && errno != ERANGE;
        if (number && (!whole || (std::isfinite(v) && v == std::floor(v))) && ok(v)) return {};
        return "must be " + expected + ", got " + (in.empty() ? "nothing" : in);
      },
      expected, "");
}

const CLI::Validator kSeconds =
    numberCheck("a positive number of seconds", [](double v) { return !(v <= 0); });
const CLI::Validator kWatchdogSeconds = numberCheck("a number of seconds, 0 or more (0: no watchdog)",
                                                    [](double v) { return v >= 0 && std::isfinite(v); });
CLI::Validator positiveWhole(const std::string& what) {
  return numberCheck(
      "a positive whole number of " + what, [](double v) { return v >= 1 && v <= 9e18; }, true);
}
const CLI::Validator kThreads = numberCheck(
    "a whole number of threads from 1 to 256", [](double v) { return v >= 1 && v <= 256; }, true);
/// A seed: a whole number from 0 to 2^63 - 1, in digits (no sign, no exponent, no wrap-around).
const CLI::Validator kSeed(
    [](std::string& in) -> std::string {
      const bool digits =
          !in.empty() && in.size() <= 19 && in.find_first_not_of("0123456789") == std::string::npos;
      if (digits && std::strtoull(in.c_str(), nullptr, 10) <= 9223372036854775807ull) return {};
      return "must be a whole number from 0 to 9223372036854775807, got " +
             (in.empty() ? std::string("nothing") : in);
    },
    "SEED", "");
const CLI::Validator kChunk = numberCheck(
    "a whole number of modules from 1 to 1000000", [](double v) { return v >= 1 && v <= 1e6; }, true);

}  // namespace

int run(int argc, char** argv) {
  CLI::App app{"RM3D: a physics-based simulator for self-reconfigurable modular robots"};
  app.require_subcommand(1);
  std::string root;
  app.add_option("--root", root,
                 "project root (assets/, lua/, behaviors/); default: where rm3d is installed, then "
                 "$RM3D_ROOT, then the current project")
      ->check(CLI::ExistingDirectory);
  app.set_version_flag("--version", "rm3d " + rm3dVersion(), "print the version (and git revision) and exit");

  rm3d::RunArgs run;
  CLI::App* runCmd = app.add_subcommand("run", "run a world headless");
  runCmd->add_option("world", run.world, "world script (.lua)")->required();
  bool headless = true;
  runCmd->add_flag("--headless", headless, "no window (runs are always headless; `view` opens a window)");
  auto* secOpt =
      runCmd->add_option("--seconds", run.seconds, "simulated seconds (default: the world's duration)")
          ->check(kSeconds);
  runCmd->add_option("--steps", run.steps, "number of steps")
      ->check(positiveWhole("steps"))
      ->excludes(secOpt);
  runCmd->add_option("--seed", run.seed, "world seed (overrides world.set{seed=})")->check(kSeed);
  runCmd->add_option("--param", run.params, "key=value, seen as args.key in the world script")->take_all();
  runCmd->add_option("--json", run.json, "write the run summary as JSON");
  runCmd->add_flag("--strict", run.strict, "a module fault ends the run with exit code 1");
  const char* threadsHelp =
      "worker threads: behaviours, contacts, docking, solver batches, integration (same results at any "
      "count)";
  runCmd->add_option("--threads", run.threads, threadsHelp)->check(kThreads);
  const char* chunkHelp = "modules a worker thread takes at a time (default 16)";
  runCmd->add_option("--chunk", run.chunk, chunkHelp)->check(kChunk);
  runCmd->add_option("--png", run.png, "write the last frame as PNG");
  runCmd->add_option("--video", run.video, "write a video (MP4)");
  runCmd->add_option("--size", run.size, "picture size WxH (default 1280x720)");
  runCmd->add_option("--frames", run.frames, "write a PNG every --every steps into this folder");
  runCmd
      ->add_option("--every", run.every,
                   "steps between frames for --frames and --video (default: 30 frames per second)")
      ->check(positiveWhole("steps"));
  runCmd->add_option("--graph", run.graph,
                     "write the connection graph at the end (FILE.dot: Graphviz, else JSON)");
  runCmd->add_flag("--quiet", run.quiet, "no module log lines");
  runCmd->add_flag("--watch", run.watch,
                   "run in real time and reload behaviours, lua/ and the world as they are saved");
  const char* watchdogHelp = "stop a run that hangs this many seconds of wall time (exit code 3)";
  runCmd->add_option("--watchdog", run.watchdog, watchdogHelp)->check(kWatchdogSeconds);
  runCmd
      ->add_option("--memory-budget", run.memoryBudget,
                   "MiB for everything the world script adds: bodies, modules, cloth, particles (default "
                   "2048; docs/limits.md)")
      ->check(CLI::Range(1.0, 1048576.0));
  runCmd->add_option(
      "--trace", run.trace,
      "write a time series as CSV: a row per module per traced step (README: Traces and plots)");
  runCmd->add_option("--trace-every", run.traceEvery, "steps between traced rows for --trace (default 1)")
      ->check(positiveWhole("steps"));
  run.commandLine.assign(argv, argv + argc);
  runCmd->add_option("--record", run.record,
                     "record every step (poses, docks, events, sources) for replay and fork");
  runCmd->add_option("--fork", run.fork,
                     "re-simulate this recording to --at T, then go on with the files on disk");
  const CLI::Validator kTime =
      numberCheck("a time in simulated seconds, 0 or more", [](double v) { return v >= 0 && v <= 1e9; });
  runCmd->add_option("--at", run.at, "the time to fork at (with --fork)")->check(kTime);
  const char* eyeHelp = "camera position X,Y,Z for pictures (default: world.camera, else framing the scene)";
  const char* targetHelp = "point the camera looks at, X,Y,Z";
  const char* fovHelp = "camera vertical field of view, degrees (default 45)";
  runCmd->add_option("--eye", run.eye, eyeHelp);
  runCmd->add_option("--target", run.target, targetHelp);
  runCmd->add_option("--fov", run.fov, fovHelp);
  const char* htmlHelp =
      "write the run as one web page that opens from disk in a browser: 3D view, time slider, "
      "connection graph (docs/replay-html.md)";
  runCmd->add_option("--html", run.html, htmlHelp);
  const char* labelsHelp = "write each module's name above it in --png, --frames and --video pictures";
  runCmd->add_flag("--labels", run.labels, labelsHelp);

  rm3d::ReplayArgs replay;
  CLI::App* replayCmd = app.add_subcommand(
      "replay", "draw a recording (rm3d run --record) again, offscreen or with --view in a window");
  replayCmd->add_option("recording", replay.file, "recording file")->required();
  replayCmd->add_option("--png", replay.png, "write the last frame (or the one at --at) as PNG");
  replayCmd->add_option("--video", replay.video, "write a video (MP4)");
  replayCmd->add_option("--frames", replay.frames, "write a PNG every --every steps into this folder");
  replayCmd->add_option("--every", replay.every, "steps between frames (default: 30 frames per second)")
      ->check(positiveWhole("steps"));
  replayCmd->add_option("--size", replay.size, "picture size WxH (default 1280x720)");
  replayCmd->add_option("--at", replay.at, "the frame for --png and --json, in simulated seconds")
      ->check(kTime);
  replayCmd->add_option("--json", replay.json, "write the state at --at (or the last frame) as JSON");
  replayCmd->add_option("--eye", replay.eye, eyeHelp);
  replayCmd->add_option("--target", replay.target, targetHelp);
  replayCmd->add_option("--fov", replay.fov, fovHelp);
  replayCmd->add_option("--html", replay.html, htmlHelp);
  replayCmd->add_flag("--labels", replay.labels, labelsHelp);
  replayCmd->add_flag("--view", replay.view, "show it in a window with a time slider and play/pause");
  // Hidden: with --view, draw N frames, save the window as PNG and exit (tests).
  replayCmd->add_option("--view-frames", replay.viewFrames, "frames to draw")
      ->group("")
      ->check(positiveWhole("frames"));
  replayCmd->add_option("--screenshot", replay.screenshot, "PNG of the last window frame")->group("");

  rm3d::TestArgs test;
  CLI::App* testCmd =
      app.add_subcommand("test", "run scripted test worlds headless; ends with 'N passed, N failed'");
  testCmd->add_option("paths", test.paths, "world files or folders (default: tests/worlds)");
  testCmd->add_option("--junit", test.junit, "write a JUnit XML report");
  testCmd->add_option("--threads", test.threads, threadsHelp)->check(kThreads);
  testCmd->add_option("--chunk", test.chunk, chunkHelp)->check(kChunk);
  testCmd->add_flag("--strict", test.strict,
                    "a module fault fails the world at once (even with world.set{expect_faults=})");
  testCmd->add_option("--watchdog", test.watchdog, watchdogHelp)->check(kWatchdogSeconds);

  rm3d::BenchArgs bench;
  CLI::App* benchCmd = app.add_subcommand(
      "bench", "scale benchmarks: the paper's scale table (snake_150 ... atrons_1500) and more");
  benchCmd->add_option("scenes", bench.scenes, "scene names (default: all; listed below)");
  benchCmd->footer(rm3d::benchSceneHelp());
  benchCmd->add_option("--dt", bench.dt, "control step, s (default: the world's)")
      ->check(
          numberCheck("a positive number of seconds", [](double v) { return v > 0 && std::isfinite(v); }));
  auto* benchSteps =
      benchCmd->add_option("--steps", bench.steps, "measured steps per scene")->check(positiveWhole("steps"));
  benchCmd
      ->add_option("--threads", bench.threads,
                   "worker threads as in run; several counts (1,2) build one world each, measured in turns, "
                   "with their speed ratios and whether their states are the same bits")
      ->delimiter(',')
      ->allow_extra_args(false)
      ->check(kThreads);
  benchCmd
      ->add_option("--rounds", bench.rounds,
                   "blocks the measured steps are split into, each world in turn (default 1; 4 with several "
                   "thread counts)")
      ->check(positiveWhole("rounds"));
  benchCmd
      ->add_option("--modules", bench.modules, "modules per scene (default: the scene's, as its name says)")
      ->check(positiveWhole("modules"));
  benchCmd->add_option("--iterations", bench.iterations, "solver iterations (default: the world's)")
      ->check(positiveWhole("iterations"));
  benchCmd->add_option("--substeps", bench.substeps, "physics substeps per step (default: the world's)")
      ->check(positiveWhole("substeps"));
  benchCmd->add_option("--solver", bench.solver, "joint solver: pgs or exact (default: the world's)")
      ->check(CLI::IsMember({"pgs", "exact"}));
  benchCmd
      ->add_option("--joint-iterations", bench.jointIterations,
                   "solver iterations for hinge rows (default: as --iterations)")
      ->check(numberCheck(
          "a whole number of iterations, 0 or more", [](double v) { return v >= 0 && v <= 1e9; }, true));
  benchCmd->add_option("--type", bench.type,
                       "SuperBot scenes' module type (default superbot; superbot_box: brackets as boxes)");
  benchCmd->add_option("--json", bench.json, "write results as JSON");
  benchCmd->add_flag(
      "--together", bench.together,
      "build every scene's worlds first and measure them all in turns (--rounds, default 4): each "
      "scene's CPU a step against the first's, round by round");
  benchCmd->add_flag(
      "--converged", bench.converged,
      "the 10-module snake for 2 s at the world's defaults against a converged run (20 substeps x "
      "100 iterations): largest joint, position and dock-load differences; exit 1 above 1 deg, 2 mm, "
      "10%");

  rm3d::ViewArgs view;
  CLI::App* viewCmd =
      app.add_subcommand("view", "interactive window: real-time stepping, inspector, hot reload");
  viewCmd->add_option("world", view.world, "world script (.lua)")->required();
  viewCmd->add_option("--seed", view.seed, "world seed (overrides world.set{seed=})")->check(kSeed);
  viewCmd->add_option("--param", view.params, "key=value, seen as args.key in the world script")->take_all();
  viewCmd->add_option("--threads", view.threads, threadsHelp)->check(kThreads);
  viewCmd->add_option("--chunk", view.chunk, chunkHelp)->check(kChunk);
  viewCmd->add_flag("--quiet", view.quiet,
                    "no module log lines on the terminal (the inspector still shows them)");
  viewCmd->add_option("--exit-after", view.frames, "render this many frames, then exit (with --screenshot)")
      ->check(positiveWhole("frames"));
  // `--frames` is a folder of PNG frames (as in `run`); `view --frames N`, the old spelling of
  // --exit-after N, still works with a deprecation warning.
  std::string viewFramesOld;
  viewCmd->add_option("--frames", viewFramesOld, "deprecated: use --exit-after N")->group("");
  viewCmd->add_option("--screenshot", view.screenshot,
                      "save the last frame's window as PNG (needs --exit-after)");
  viewCmd->add_option("--watchdog", view.watchdog, watchdogHelp)->check(kWatchdogSeconds);
  viewCmd->add_flag("!--no-graph", view.graph, "start with the connection-graph panel hidden (G shows it)");
  viewCmd->add_flag("--components", view.components,
                    "colour modules by connected component, as in the graph panel (C toggles)");
  // Hidden: opens the inspector on a module at start (tests, README pictures).
  viewCmd->add_option("--select", view.select, "module id to select at start")->group("");

  rm3d::PlotArgs plot;
  CLI::App* plotCmd =
      app.add_subcommand("plot", "plot columns of a --trace CSV as PNG or SVG (through gnuplot)");
  plotCmd
      ->add_option("file", plot.file,
                   "CSV file with a header row (rm3d run --trace), or JSON lines (rm3d sweep --out)")
      ->required();
  plotCmd->add_option("--y", plot.y, "columns to plot (repeat, or a,b,c)")->required()->delimiter(',');
  plotCmd->add_option("--x", plot.x, "column along x (default: time)");
  plotCmd->add_option("--module", plot.modules,
                      "only this module, by name or id (repeat for more; default: all)");
  plotCmd->add_option("--out", plot.out, "FILE.png or FILE.svg (default: the CSV's name with .png)");
  plotCmd->add_option("--title", plot.title, "title above the plot");
  plotCmd->add_option("--xlabel", plot.xlabel,
                      "label of the x axis (default: the column; 'time (s)' for time)");
  plotCmd->add_option("--ylabel", plot.ylabel, "label of the y axis (default: the column, when one)");
  plotCmd->add_option("--size", plot.size, "picture size WxH (default 1000x600)");
  plotCmd->add_option("--by", plot.by,
                      "one line per value of this column (default: module; e.g. params.period for a sweep)");
  plotCmd->add_flag("--mean", plot.mean,
                    "per x value, the mean of y and its standard deviation as error bars (e.g. over seeds)");

  rm3d::SweepArgs sweep;
  CLI::App* sweepCmd = rm3d::addSweepCommand(app, sweep);

  CLI::App* worldsCmd = app.add_subcommand(
      "worlds", "list the shipped sample worlds (in the data root's worlds/; run one from any folder)");
  std::string initDir;
  CLI::App* initCmd = app.add_subcommand(
      "init", "make a project folder for your own worlds and behaviours, with a .luarc.json for editors");
  initCmd->add_option("dir", initDir, "the folder to make (existing files are never overwritten)")
      ->required();

  // Before parsing: CLI11 would first insist on a subcommand.
  if (argc == 2 && std::string(argv[1]) == "--version") {
    std::printf("rm3d %s\n", rm3dVersion().c_str());
    return 0;
  }
  if (argc > 1 && argv[1][0] != '-') {
    const std::string cmd = argv[1];
    if (cmd != "run" && cmd != "test" && cmd != "bench" && cmd != "view" && cmd != "plot" &&
        cmd != "replay" && cmd != "sweep" && cmd != "worlds" && cmd != "init") {
      std::fprintf(stderr,
                   "rm3d: unknown command '%s' (expected run, test, bench, view, plot, replay, sweep, worlds "
                   "or init; see rm3d --help)\n",
                   cmd.c_str());
      return 2;
    }
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    // "--steps: must be ..." from numberCheck reads "--steps must be ...".
    std::string msg = e.what();
    const size_t at = msg.find(": must be ");
    if (at != std::string::npos && msg.compare(0, 2, "--") == 0) msg.erase(at, 1);
    const CLI::App* sub = app.get_subcommands().empty() ? nullptr : app.get_subcommands().front();
    const std::string help = sub ? "rm3d " + sub->get_name() + " --help" : "rm3d --help, or rm3d run --help";
    std::fprintf(stderr, "rm3d: %s\n(see %s)\n", msg.c_str(), help.c_str());
    return 2;
  }
  const rm3d::DataRoot dataRoot = rm3d::findDataRoot(root);
  if (dataRoot.path.empty()) {
    std::fprintf(stderr, "rm3d: %s\n", dataRoot.error.c_str());
    return 2;
  }
  const std::string& r = dataRoot.path;
  // A shipped world named from another folder (rm3d run worlds/snake.lua in /tmp) is the data root's.
  auto resolve = [&r](std::string& path) {
    std::string note;
    path = rm3d::resolveWorldPath(path, r, &note);
    if (!note.empty()) std::fprintf(stderr, "rm3d: %s\n", note.c_str());
  };
  if (*worldsCmd) return rm3d::listWorldsCommand(r);
  if (*initCmd) return rm3d::initProjectCommand(initDir, r);
  if (*runCmd) resolve(run.world);
  if (*viewCmd) resolve(view.world);
  if (*sweepCmd) resolve(sweep.world);
  if (*testCmd)
    for (std::string& p : test.paths) resolve(p);
  if (*runCmd) return rm3d::runCommand(run, r);
  if (*replayCmd) return rm3d::replayCommand(replay);
  if (*testCmd) return rm3d::testCommand(test, r);
  if (*benchCmd) {
    bench.stepsGiven = benchSteps->count() > 0;
    return bench.converged ? rm3d::convergedCommand(bench, r) : rm3d::benchCommand(bench, r);
  }
  if (*viewCmd) {
    if (!viewFramesOld.empty()) {
      std::string n = viewFramesOld;
      if (!positiveWhole("frames")(n).empty()) {
        std::fprintf(
            stderr,
            "rm3d view: --frames %s: the viewer writes no frame folders (--frames DIR is `run`'s); to "
            "stop after N frames give --exit-after N\n",
            viewFramesOld.c_str());
        return 2;
      }
      std::fprintf(stderr,
                   "rm3d view: --frames N is deprecated, use --exit-after N (--frames means a folder of PNG "
                   "frames, as in `rm3d run`)\n");
      view.frames = int(std::strtol(viewFramesOld.c_str(), nullptr, 10));
    }
    return rm3d::viewCommand(view, r);
  }
  if (*plotCmd) return rm3d::plotCommand(plot);
  if (*sweepCmd) return rm3d::sweepCommand(sweep, r);
  return 2;
}

int main(int argc, char** argv) {
  // A reader that goes away (ffmpeg, `| head`) is an error from write(), not a silent death.
  std::signal(SIGPIPE, SIG_IGN);
  // Line by line, also into a pipe or file: stdout's lines ("wrote ...", the summary) then keep
  // their place among stderr's (log lines, warnings) when both go to the same place.
  std::setvbuf(stdout, nullptr, _IOLBF, 0);
  try {
    return run(argc, argv);
  } catch (const std::exception& e) {
    std::fflush(stdout);
    std::fprintf(stderr, "rm3d: error: %s\n", e.what());
  } catch (...) {
    std::fflush(stdout);
    std::fprintf(stderr, "rm3d: error: an unknown exception\n");
  }
  return 2;
}
