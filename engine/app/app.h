// The command line: `rm3d run`, `rm3d test`, `rm3d bench`, `rm3d view`.
#pragma once

#include <map>
#include <optional>
#include <string>
#include <vector>

namespace rm3d {

struct RunArgs {
  std::string world;
  std::optional<double> seconds;
  std::optional<long long> steps;
  std::optional<unsigned long long> seed;
  std::vector<std::string> params;  ///< key=value
  std::string json;
  bool strict = false;
  int threads = 1;
  int chunk = 16;  ///< --chunk N (RunOptions::chunkSize)
  std::string png, video;
  std::string size;    ///< WxH for pictures
  std::string frames;  ///< folder for PNG frames
  int every = 0;       ///< steps between frames (0: 30 per second)
  std::string graph;   ///< connection graph at the end (.dot: Graphviz, else JSON)
  bool quiet = false;
  bool watch = false;                    ///< real time, reload edits
  double watchdog = 5;                   ///< --watchdog S (RunOptions::watchdogSeconds)
  double memoryBudget = 2048;            ///< --memory-budget MIB (RunOptions::memoryBudget)
  std::string trace;                     ///< --trace FILE.csv (io/trace_writer.h)
  int traceEvery = 0;                    ///< --trace-every N (0: not given, every step)
  std::vector<std::string> commandLine;  ///< argv as given, for the summary
  // Record, replay, fork (io/run_capture.h, app/fork.h) and the camera of pictures.
  std::string record;            ///< --record FILE
  std::string fork;              ///< --fork FILE (with --at T)
  std::optional<double> at;      ///< --at T
  std::string eye, target, fov;  ///< --eye X,Y,Z --target X,Y,Z --fov DEG
  std::string html;              ///< --html FILE: the run as a web page (app/html_replay.h)
  bool labels = false;           ///< --labels: pictures name every module
};

/// `rm3d replay FILE`: a recording drawn again, offscreen or in a window (app/cmd_replay.cpp).
struct ReplayArgs {
  std::string file;
  std::string png, video, frames, size, json;
  int every = 0;             ///< steps between frames (0: 30 per second)
  std::optional<double> at;  ///< --at T: the frame for --png / --json (default: the last)
  std::string eye, target, fov;
  bool view = false;       ///< --view: a window with a time slider
  int viewFrames = 0;      ///< hidden --view-frames N: draw N frames, save --screenshot, exit (tests)
  std::string screenshot;  ///< hidden --screenshot FILE
  std::string html;        ///< --html FILE: the recording as a web page (app/html_replay.h)
  bool labels = false;     ///< --labels: pictures name every module
};

struct TestArgs {
  std::vector<std::string> paths;
  std::string junit;
  int threads = 1;
  int chunk = 16;  ///< --chunk N (RunOptions::chunkSize)
  bool strict = false;
  double watchdog = 5;  ///< --watchdog S
};

struct BenchArgs {
  std::vector<std::string> scenes;
  std::optional<double> dt;
  long long steps = 300;
  bool stepsGiven = false;      ///< --steps was on the command line
  std::vector<int> threads{1};  ///< one world per count, measured in turns (rounds)
  int rounds = 0;               ///< blocks of steps per world (0: 1 for one count, 4 for several)
  std::optional<int> modules;
  std::optional<int> iterations;
  std::optional<int> substeps;
  std::optional<std::string> solver;  ///< "pgs" or "exact"
  std::optional<int> jointIterations;
  std::string type = "superbot";
  std::string json;
  bool converged = false;  ///< --converged: the converged reference (bench_converged.cpp)
  bool together = false;   ///< --together: every scene's worlds built first and measured in turns
};

struct PlotArgs {
  std::string file;                   ///< CSV with a header row (a --trace file)
  std::vector<std::string> y;         ///< columns to plot
  std::string x;                      ///< default: time (else the first column)
  std::vector<std::string> modules;   ///< --module NAME|ID (default: all)
  std::string out;                    ///< .png or .svg (default: FILE with .png)
  std::string title, xlabel, ylabel;  ///< axis labels default to the columns' names
  std::string size;                   ///< WxH
  std::string by;                     ///< --by COLUMN: one line per value of this column (default: module)
  bool mean = false;  ///< --mean: per x value, the mean of y with its standard deviation as bars
};

/// Exit codes (run_world.h, ExitCode; README "Exit codes"): 0 ok; 1 failed expectations, a fault
/// under --strict (any unexpected fault under `rm3d test`); 2 bad input or an output that could
/// not be written; 3 the watchdog stopped a hung run; 130 / 143 interrupted by SIGINT / SIGTERM
/// (the summary is still written). When several apply, the highest wins.
int runCommand(const RunArgs& a, const std::string& root);
int testCommand(const TestArgs& a, const std::string& root);
int replayCommand(const ReplayArgs& a);
int benchCommand(const BenchArgs& a, const std::string& root);
/// `rm3d plot`: line plots of a CSV trace through gnuplot (app/cmd_plot.cpp).
int plotCommand(const PlotArgs& a);
/// `rm3d bench --converged`: the 10-module snake at the world's defaults against a converged run
/// (20 substeps x 100 iterations); exit code 1 when a difference exceeds its threshold.
int convergedCommand(const BenchArgs& a, const std::string& root);

/// Parses ["k=v", ...]; false and err on a malformed entry.
bool parseParams(const std::vector<std::string>& in, std::map<std::string, std::string>& out,
                 std::string& err);

}  // namespace rm3d
