// `rm3d sweep` (sweep.h): expands the runs, skips those already in the output, runs the rest as
// child `rm3d run` processes (a crash stays in its child) and appends one JSON line per run; or
// writes a Slurm job array whose tasks run `rm3d sweep --array-task I` on their share of runs.
#include <fcntl.h>
#include <spawn.h>
#include <sys/file.h>
#include <sys/wait.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>

#include "app/run_world.h"
#include "app/sweep.h"
#include "core/version.h"

extern char** environ;

namespace fs = std::filesystem;
using nlohmann::json;

namespace rm3d {

namespace {

constexpr long long kMaxRuns = 10'000'000;

std::vector<std::string> split(const std::string& s, char sep) {
  std::vector<std::string> out;
  size_t start = 0;
  for (;;) {
    const size_t at = s.find(sep, start);
    out.push_back(s.substr(start, at == std::string::npos ? std::string::npos : at - start));
    if (at == std::string::npos) return out;
    start = at + 1;
  }
}

bool wholeNumber(const std::string& s, unsigned long long& v) {
  if (s.empty() || s.size() > 19 || s.find_first_not_of("0123456789") != std::string::npos) return false;
  v = std::strtoull(s.c_str(), nullptr, 10);
  return v <= 9223372036854775807ull;
}

/// A value as the world's `args` sees it: numbers and true/false typed, the rest strings.
json typed(const std::string& v) {
  if (v == "true") return true;
  if (v == "false") return false;
  if (!v.empty() && v.find_first_not_of("+-0123456789") == std::string::npos && v.size() < 19) {
    char* end = nullptr;
    const long long i = std::strtoll(v.c_str(), &end, 10);
    if (end && *end == '\0') return i;
  }
  char* end = nullptr;
  const double d = std::strtod(v.c_str(), &end);
  if (!v.empty() && end && *end == '\0' && std::isfinite(d) && !std::isspace((unsigned char)v[0])) return d;
  return v;
}

json paramsJson(const SweepRun& r) {
  json p = json::object();
  for (const auto& [k, v] : r.params) p[k] = typed(v);
  return p;
}

std::string keyOf(const json& params, const json& seed) {
  return json{{"params", params}, {"seed", seed}}.dump();
}

/// Keys of the runs already in the output file (lines that parse; a torn last line does not).
std::set<std::string> finishedRuns(const std::string& out) {
  std::set<std::string> done;
  std::ifstream in(out, std::ios::binary);
  std::string line;
  while (std::getline(in, line)) {
    const json j = json::parse(line, nullptr, false);
    if (j.is_object() && j.contains("params") && j.contains("seed"))
      done.insert(keyOf(j["params"], j["seed"]));
  }
  return done;
}

/// Appends one line under an exclusive lock (array tasks on several nodes share the file).
bool appendLine(const std::string& out, const std::string& line, std::string& err) {
  const int fd = ::open(out.c_str(), O_RDWR | O_APPEND | O_CREAT | O_CLOEXEC, 0644);
  if (fd < 0) {
    err = "--out " + out + ": cannot write (" + std::strerror(errno) + ")";
    return false;
  }
  struct flock lk {};
  lk.l_type = F_WRLCK;
  lk.l_whence = SEEK_SET;
  while (::fcntl(fd, F_SETLKW, &lk) != 0 && errno == EINTR) {
  }
  // A line torn by a killed writer is ended first, so this one parses.
  std::string text = line + "\n";
  const off_t size = ::lseek(fd, 0, SEEK_END);
  if (size > 0) {
    char last = '\n';
    if (::pread(fd, &last, 1, size - 1) == 1 && last != '\n') text = "\n" + text;
  }
  size_t done = 0;
  while (done < text.size()) {
    const ssize_t n = ::write(fd, text.data() + done, text.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      err = "--out " + out + ": write failed (" + std::strerror(errno) + ")";
      ::close(fd);
      return false;
    }
    done += size_t(n);
  }
  ::close(fd);
  return true;
}

std::string readTail(const std::string& file, size_t max) {
  std::ifstream in(file, std::ios::binary);
  std::string s((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  return s.size() > max ? s.substr(s.size() - max) : s;
}

std::string selfExe() {
  std::error_code ec;
  const fs::path p = fs::read_symlink("/proc/self/exe", ec);
  return ec ? std::string("rm3d") : p.string();
}

/// The child's command line: `rm3d --root R run WORLD --headless --quiet --param ... --seed S --json F`.
std::vector<std::string> runArgv(const SweepArgs& a, const std::string& root, const SweepRun& r,
                                 const std::string& jsonFile) {
  std::vector<std::string> v = {selfExe(), "--root", root, "run", a.world, "--headless", "--quiet"};
  for (const auto& [k, val] : r.params) v.insert(v.end(), {"--param", k + "=" + val});
  v.insert(v.end(), {"--seed", std::to_string(r.seed), "--json", jsonFile});
  if (a.seconds) {
    std::ostringstream s;
    s.precision(17);
    s << *a.seconds;
    v.insert(v.end(), {"--seconds", s.str()});
  }
  if (a.steps) v.insert(v.end(), {"--steps", std::to_string(*a.steps)});
  if (a.strict) v.push_back("--strict");
  std::ostringstream w;
  w << a.watchdog;
  v.insert(v.end(), {"--watchdog", w.str()});
  return v;
}

struct Child {
  size_t index = 0;
  std::string jsonFile, logFile;
};

/// Starts a run; its pid, or -1 with `error` (posix_spawn's own code: it does not set errno).
pid_t spawnRun(const std::vector<std::string>& argv, const std::string& logFile, int& error) {
  posix_spawn_file_actions_t fa;
  posix_spawn_file_actions_init(&fa);
  posix_spawn_file_actions_addopen(&fa, 1, logFile.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&fa, 1, 2);
  posix_spawn_file_actions_addopen(&fa, 0, "/dev/null", O_RDONLY, 0);
  std::vector<char*> args;
  for (const std::string& s : argv) args.push_back(const_cast<char*>(s.c_str()));
  args.push_back(nullptr);
  pid_t pid = -1;
  const int rc = posix_spawn(&pid, args[0], &fa, nullptr, args.data(), environ);
  posix_spawn_file_actions_destroy(&fa);
  error = rc;
  return rc == 0 ? pid : -1;
}

/// The output line of a finished run.
nlohmann::ordered_json resultLine(const SweepArgs& a, const SweepRun& r, int status, const Child& c) {
  using ojson = nlohmann::ordered_json;
  ojson line;
  line["world"] = a.world;
  line["params"] = ojson::parse(paramsJson(r).dump());
  line["seed"] = r.seed;
  line["version"] = rm3dVersion();
  int code = 0;
  if (WIFEXITED(status)) {
    code = WEXITSTATUS(status);
  } else if (WIFSIGNALED(status)) {
    code = 128 + WTERMSIG(status);
    line["signal"] = strsignal(WTERMSIG(status));
  }
  line["exit_code"] = code;
  std::ifstream in(c.jsonFile, std::ios::binary);
  ojson summary = in ? ojson::parse(in, nullptr, false) : ojson();
  if (summary.is_discarded()) summary = nullptr;
  line["metrics"] = summary.is_object() && summary.contains("metrics") ? summary["metrics"] : ojson::object();
  if (code != 0) line["output_tail"] = readTail(c.logFile, 2000);
  line["summary"] = summary;
  return line;
}

class Progress {
 public:
  Progress(size_t total, size_t skipped) : m_total(total), m_skipped(skipped), m_tty(::isatty(2)) {}
  void update(size_t done, size_t failed, size_t running, bool last = false) {
    const double secs = std::chrono::duration<double>(Clock::now() - m_start).count();
    const size_t todo = m_total - m_skipped;
    char eta[64] = "";
    if (done > 0 && done < todo)
      std::snprintf(eta, sizeof eta, ", about %.0f s left", secs / double(done) * double(todo - done));
    std::fprintf(
        stderr, "%ssweep: %zu/%zu runs done (%zu failed, %zu running, %zu already in the output), %.0f s%s%s",
        m_tty ? "\r\033[K" : "", done, todo, failed, running, m_skipped, secs, eta,
        m_tty && !last ? "" : "\n");
    std::fflush(stderr);
  }

 private:
  using Clock = std::chrono::steady_clock;
  size_t m_total, m_skipped;
  bool m_tty;
  Clock::time_point m_start = Clock::now();
};

/// Runs `runs` (indices into all) `jobs` at a time; appends a line per run. Returns the exit code.
int runLocal(const SweepArgs& a, const std::string& root, const std::vector<SweepRun>& all,
             const std::vector<size_t>& todo, size_t skipped) {
  // Each sweep process keeps its runs' files in a folder of its own under OUT.runs: the tasks of a
  // Slurm array share OUT, and one task that finished and took away a shared (empty) folder left
  // another's next run without a place for its log (the spawn failed: "cannot start").
  const fs::path runs = fs::path(a.out + ".runs");
  const fs::path work = runs / ("p" + std::to_string(::getpid()));
  std::error_code ec;
  // (Another process may take away the empty OUT.runs between making it and making ours in it.)
  for (int attempt = 0; attempt < 8; ++attempt) {
    ec.clear();
    fs::create_directories(work, ec);
    if (!ec) break;
  }
  if (ec) {
    std::fprintf(stderr, "rm3d sweep: cannot make %s for the runs' files (%s)\n", work.c_str(),
                 ec.message().c_str());
    return kExitBadInput;
  }
  Progress progress(skipped + todo.size(), skipped);
  std::map<pid_t, Child> running;
  size_t next = 0, done = 0, failed = 0;
  bool startFailed = false;  // a run could not start: no more are started; those running finish
  progress.update(0, 0, 0);
  while ((!startFailed && next < todo.size()) || !running.empty()) {
    while (!interruptSignal() && !startFailed && next < todo.size() && running.size() < size_t(a.jobs)) {
      Child c;
      c.index = todo[next++];
      const std::string stem = "run_" + std::to_string(c.index) + "_" + std::to_string(::getpid());
      c.jsonFile = (work / (stem + ".json")).string();
      c.logFile = (work / (stem + ".log")).string();
      fs::remove(c.jsonFile, ec);
      int error = 0;
      const pid_t pid = spawnRun(runArgv(a, root, all[c.index], c.jsonFile), c.logFile, error);
      if (pid < 0) {
        std::fprintf(stderr, "\nrm3d sweep: cannot start %s with its log %s (%s)\n", selfExe().c_str(),
                     c.logFile.c_str(), std::strerror(error));
        startFailed = true;
        break;
      }
      running.emplace(pid, c);
    }
    if (running.empty()) break;
    int status = 0;
    const pid_t pid = ::waitpid(-1, &status, 0);
    if (pid < 0) {
      if (errno == EINTR) continue;
      break;
    }
    auto it = running.find(pid);
    if (it == running.end()) continue;
    const Child c = it->second;
    running.erase(it);
    const auto line = resultLine(a, all[c.index], status, c);
    const int code = line["exit_code"].get<int>();
    // A run cut short by our own Ctrl-C is not a result: left out, so a resumed sweep reruns it.
    const bool interrupted = interruptSignal() && (code == kExitSigint || code == kExitSigterm);
    if (!interrupted) {
      std::string err;
      if (!appendLine(a.out, line.dump(-1, ' ', false, nlohmann::ordered_json::error_handler_t::replace),
                      err)) {
        std::fprintf(stderr, "\nrm3d sweep: %s\n", err.c_str());
        return kExitBadInput;
      }
      ++done;
      if (code != 0) ++failed;
    }
    fs::remove(c.jsonFile, ec);
    fs::remove(c.logFile, ec);
    progress.update(done, failed, running.size(), next >= todo.size() && running.empty());
  }
  fs::remove(work, ec);  // only when empty
  fs::remove(runs, ec);  // the same: another process's folder may still be in it
  if (startFailed) {
    std::fprintf(stderr, "rm3d sweep: %zu runs not started (run the same command again to resume)\n",
                 todo.size() - done);
    return kExitBadInput;
  }
  if (interruptSignal()) {
    std::fprintf(stderr,
                 "rm3d sweep: interrupted; %zu runs not done (run the same command again to resume)\n",
                 todo.size() - done);
    return 128 + interruptSignal();
  }
  if (failed)
    std::fprintf(stderr, "rm3d sweep: %zu of %zu runs exited non-zero (see exit_code)\n", failed, done);
  return failed ? kExitFailed : kExitOk;
}

std::string shellQuote(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

int writeSlurm(const SweepArgs& a, const std::string& root, size_t total, size_t todo) {
  const long long per = a.runsPerTask;
  const long long tasks = (static_cast<long long>(total) + per - 1) / per;
  const std::string script = a.script.empty() ? a.out + ".slurm.sh" : a.script;
  const fs::path outAbs = fs::absolute(a.out).lexically_normal();
  const fs::path logs = outAbs.parent_path() / (outAbs.filename().string() + ".slurm-logs");
  std::error_code ec;
  fs::create_directories(logs, ec);
  std::ostringstream s;
  s << "#!/bin/bash\n"
    << "# rm3d sweep as a Slurm job array: " << total << " runs, " << per << " per array task.\n"
    << "# Each task runs its share with `rm3d sweep --array-task N` (child `rm3d run` processes) and\n"
    << "# appends one JSON line per run to the output under a file lock; runs already there are skipped,\n"
    << "# so resubmitting this script finishes what is missing.\n"
    << "#SBATCH --job-name=rm3d-sweep\n"
    << "#SBATCH --array=0-" << tasks - 1 << "\n"
    << "#SBATCH --ntasks=1\n"
    << "#SBATCH --cpus-per-task=1\n"
    << "#SBATCH --output=" << (logs / "task-%A_%a.log").string() << "\n";
  for (const std::string& o : a.slurmOptions) s << "#SBATCH " << o << "\n";
  s << "set -eu\n"
    << "cd " << shellQuote(fs::current_path().string()) << "\n"
    << "exec " << shellQuote(selfExe()) << " --root " << shellQuote(root) << " sweep " << shellQuote(a.world);
  for (const std::string& p : a.params) s << " --param " << shellQuote(p);
  s << " --seeds " << shellQuote(a.seeds) << " --out " << shellQuote(outAbs.string()) << " --jobs 1";
  if (a.seconds) s << " --seconds " << *a.seconds;
  if (a.steps) s << " --steps " << *a.steps;
  if (a.strict) s << " --strict";
  s << " --watchdog " << a.watchdog << " --runs-per-task " << per
    << " --array-task \"$SLURM_ARRAY_TASK_ID\"\n";
  {
    std::ofstream f(script, std::ios::binary);
    f << s.str();
    if (!f.flush()) {
      std::fprintf(stderr, "rm3d sweep: --script %s: cannot write\n", script.c_str());
      return kExitBadInput;
    }
  }
  fs::permissions(script, fs::perms::owner_exec | fs::perms::group_exec | fs::perms::others_exec,
                  fs::perm_options::add, ec);
  std::printf("wrote %s: a job array of %lld tasks for %zu runs (%zu not yet in %s)\n", script.c_str(), tasks,
              total, todo, a.out.c_str());
  if (a.dryRun) {
    std::printf("not submitted (--dry-run); submit with: sbatch %s\n", script.c_str());
    return 0;
  }
  std::vector<std::string> argv = {"sbatch"};
  if (a.wait) argv.push_back("--wait");
  argv.push_back(script);
  std::vector<char*> args;
  for (const std::string& x : argv) args.push_back(const_cast<char*>(x.c_str()));
  args.push_back(nullptr);
  std::fflush(stdout);
  pid_t pid = -1;
  if (posix_spawnp(&pid, "sbatch", nullptr, nullptr, args.data(), environ) != 0) {
    std::fprintf(stderr,
                 "rm3d sweep: --slurm: cannot run sbatch (%s); is Slurm installed here? The script is "
                 "written: %s\n",
                 std::strerror(errno), script.c_str());
    return kExitBadInput;
  }
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  const int code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  if (code != 0) {
    std::fprintf(stderr, "rm3d sweep: sbatch %s exited with %d\n", script.c_str(), code);
    return 1;
  }
  return 0;
}

}  // namespace

bool expandSweep(const std::vector<std::string>& params, const std::string& seeds, std::vector<SweepRun>& out,
                 std::string& err) {
  std::vector<std::pair<std::string, std::vector<std::string>>> lists;
  for (const std::string& p : params) {
    const size_t eq = p.find('=');
    if (eq == std::string::npos || eq == 0) {
      err = "--param '" + p +
            "': expected key=a,b,c (values separated by commas, or by | when a value holds commas)";
      return false;
    }
    const std::string key = p.substr(0, eq), rest = p.substr(eq + 1);
    for (const auto& l : lists)
      if (l.first == key) {
        err = "--param " + key + " is given twice (give all its values in one list: " + key + "=a,b,c)";
        return false;
      }
    lists.push_back({key, split(rest, rest.find('|') != std::string::npos ? '|' : ',')});
  }
  std::vector<unsigned long long> seedList;
  for (const std::string& part : split(seeds, ',')) {
    const size_t dash = part.find('-');
    unsigned long long lo = 0, hi = 0;
    const bool ok = dash == std::string::npos ? wholeNumber(part, lo) && (hi = lo, true)
                                              : wholeNumber(part.substr(0, dash), lo) &&
                                                    wholeNumber(part.substr(dash + 1), hi) && lo <= hi;
    if (!ok || hi - lo >= (unsigned long long)kMaxRuns) {
      err = "--seeds " + seeds +
            ": expected seeds as A-B (A <= B), a list A,B,C or both (1-10,20), whole numbers from 0; got '" +
            part + "'";
      return false;
    }
    for (unsigned long long s = lo;; ++s) {
      seedList.push_back(s);
      if (s == hi || seedList.size() > size_t(kMaxRuns)) break;
    }
  }
  // Each factor is checked before multiplying: eight lists of 256 values would overflow.
  long long total = (long long)seedList.size();
  for (const auto& l : lists)
    total = total > kMaxRuns / (long long)std::max<size_t>(l.second.size(), 1)
                ? kMaxRuns + 1
                : total * (long long)l.second.size();
  if (total > kMaxRuns) {
    err = "the sweep has more than " + std::to_string(kMaxRuns) + " runs (params x seeds); split it";
    return false;
  }
  out.clear();
  std::vector<size_t> at(lists.size(), 0);
  for (;;) {
    for (unsigned long long s : seedList) {
      SweepRun r;
      for (size_t i = 0; i < lists.size(); ++i) r.params[lists[i].first] = lists[i].second[at[i]];
      r.seed = s;
      out.push_back(std::move(r));
    }
    size_t i = lists.size();
    while (i > 0 && ++at[i - 1] == lists[i - 1].second.size()) at[--i] = 0;
    if (i == 0) break;
  }
  return true;
}

std::string sweepRunKey(const SweepRun& r) {
  return keyOf(paramsJson(r), json(r.seed));
}

CLI::App* addSweepCommand(CLI::App& app, SweepArgs& a) {
  CLI::App* c = app.add_subcommand(
      "sweep",
      "run a world over parameter values x seeds (child `rm3d run`s, N at a time, or a Slurm job array)");
  c->add_option("world", a.world, "world script (.lua)")->required();
  c->add_option(
       "--param", a.params,
       "k=a,b,c: the values of args.k to sweep (separate with | when a value holds commas); repeat for "
       "more keys (cartesian product)")
      ->take_all();
  c->add_option("--seeds", a.seeds, "seeds: A-B, A,B,C or both (default 1)");
  c->add_option("--jobs", a.jobs, "runs at a time (default 1)")->check(CLI::Range(1, 4096));
  c->add_option("--out", a.out, "output: one JSON line per run; runs already in it are skipped")->required();
  auto* sec =
      c->add_option("--seconds", a.seconds, "simulated seconds per run (default: the world's duration)")
          ->check(CLI::PositiveNumber);
  c->add_option("--steps", a.steps, "steps per run")
      ->check(CLI::Range(1LL, 9'000'000'000'000'000'000LL))
      ->excludes(sec);
  c->add_flag("--strict", a.strict, "a module fault ends a run with exit code 1");
  c->add_option("--watchdog", a.watchdog, "each run's watchdog, seconds of wall time (default 5)")
      ->check(CLI::Range(0.0, 1e9));
  c->add_flag("--slurm", a.slurm, "write a Slurm job-array script (OUT.slurm.sh) and submit it with sbatch");
  c->add_flag("--dry-run", a.dryRun, "with --slurm: write the script, do not submit it");
  c->add_flag("--wait", a.wait, "with --slurm: sbatch --wait, return when every array task has finished");
  c->add_option("--runs-per-task", a.runsPerTask, "with --slurm: runs per array task (default 1)")
      ->check(CLI::Range(1LL, 10'000'000LL));
  c->add_option("--slurm-option", a.slurmOptions,
                "with --slurm: an extra #SBATCH line, e.g. --slurm-option=--partition=short (repeatable)");
  c->add_option("--script", a.script, "with --slurm: where to write the script (default OUT.slurm.sh)");
  c->add_option("--array-task", a.arrayTask, "run one array task's share (the Slurm script uses this)")
      ->group("")
      ->check(CLI::Range(0LL, 10'000'000LL));
  return c;
}

int sweepCommand(const SweepArgs& a, const std::string& root) {
  std::vector<SweepRun> all;
  std::string err;
  if (!expandSweep(a.params, a.seeds, all, err)) {
    std::fprintf(stderr, "rm3d sweep: %s\n", err.c_str());
    return kExitBadInput;
  }
  if (!a.slurm && (a.dryRun || a.wait || !a.script.empty() || !a.slurmOptions.empty())) {
    std::fprintf(stderr, "rm3d sweep: --dry-run, --wait, --script and --slurm-option go with --slurm\n");
    return kExitBadInput;
  }
  for (const std::string& o : a.slurmOptions)
    if (o.empty() || o.find_first_of("\r\n") != std::string::npos || o.find('\0') != std::string::npos) {
      std::string shown;
      for (char c : o) shown += c == '\n' ? "\\n" : c == '\r' ? "\\r" : std::string(1, c);
      std::fprintf(
          stderr,
          "rm3d sweep: --slurm-option '%s': expected one #SBATCH option on one line (no line breaks)\n",
          shown.c_str());
      return kExitBadInput;
    }
  std::error_code ec;
  if (!fs::is_regular_file(a.world, ec)) {
    std::fprintf(stderr, "rm3d sweep: %s: cannot read world file (expected a .lua file)\n", a.world.c_str());
    return kExitBadInput;
  }
  if (!prepareOutputFile("--out", a.out, err)) {
    std::fprintf(stderr, "rm3d sweep: %s\n", err.c_str());
    return kExitBadInput;
  }
  const std::set<std::string> done = finishedRuns(a.out);
  std::vector<size_t> todo;
  size_t first = 0, last = all.size();
  if (a.arrayTask) {
    first = std::min(all.size(), size_t(*a.arrayTask * a.runsPerTask));
    last = std::min(all.size(), first + size_t(a.runsPerTask));
  }
  for (size_t i = first; i < last; ++i)
    if (!done.count(sweepRunKey(all[i]))) todo.push_back(i);
  const size_t skipped = (last - first) - todo.size();
  if (a.slurm) return writeSlurm(a, root, all.size(), todo.size());
  installInterruptHandlers();
  return runLocal(a, root, all, todo, skipped);
}

}  // namespace rm3d
