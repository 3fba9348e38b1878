// `rm3d sweep`: a world over the cartesian product of parameter values x seeds, each run a child
// `rm3d run` process, N at a time or as a Slurm job array; one JSON line per run.
#pragma once

#include <map>
#include <optional>
#include <string>
#include <vector>

namespace CLI {
class App;
}

namespace rm3d {

struct SweepArgs {
  std::string world;
  std::vector<std::string> params;  ///< "k=a,b,c" (or "k=a|b|c" when a value holds commas)
  std::string seeds = "1";          ///< "A-B", "A,B,C" or "A"
  int jobs = 1;
  std::string out;
  std::optional<double> seconds;
  std::optional<long long> steps;
  bool strict = false;
  double watchdog = 5;
  bool slurm = false;                     ///< write (and submit) a Slurm job array instead
  bool dryRun = false;                    ///< --slurm: write the script only
  bool wait = false;                      ///< --slurm: sbatch --wait (return when the array is done)
  long long runsPerTask = 1;              ///< --slurm: runs per array task
  std::vector<std::string> slurmOptions;  ///< extra #SBATCH lines ("--partition=short")
  std::string script;                     ///< --slurm: where the script goes (default OUT.slurm.sh)
  std::optional<long long> arrayTask;     ///< hidden: run only this array task's chunk
};

/// One run of a sweep: its parameter values (as given) and seed.
struct SweepRun {
  std::map<std::string, std::string> params;
  unsigned long long seed = 0;
};

/// Registers `rm3d sweep` and its options on `app`.
CLI::App* addSweepCommand(CLI::App& app, SweepArgs& args);
int sweepCommand(const SweepArgs& a, const std::string& root);

/// Expands "--param k=a,b,c" lists and a seed spec into the runs, parameters varying slowest in
/// the order given and seeds fastest. False and `err` naming the flag on malformed input.
bool expandSweep(const std::vector<std::string>& params, const std::string& seeds, std::vector<SweepRun>& out,
                 std::string& err);
/// The identity of a run in an output line: its typed params and seed as compact JSON.
std::string sweepRunKey(const SweepRun& r);

}  // namespace rm3d
