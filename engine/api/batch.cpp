// Batch and evaluate: many worlds on a pool of C++ threads. Each world is stepped by one thread
// at a time and touches only its own state and its own rows of the arrays, so the results are
// those of the same worlds stepped one by one, at any thread count.
#include <algorithm>
#include <cmath>
#include <limits>
#include <nlohmann/json.hpp>

#include "assets/mesh_loader.h"
#include "rm3d/simulation.h"
#include "world/behaviour_pool.h"

namespace rm3d::api {

namespace {

/// Runs fn(i) for i in [0, n) on the pool; errors are gathered per index and the first is thrown
/// after every call has returned ("world i: message").
void runAll(BehaviourPool& pool, int n, FunctionRef<void(int)> fn) {
  std::vector<std::string> errors(static_cast<size_t>(n));
  pool.run(
      n,
      [&](int i) {
        try {
          fn(i);
        } catch (const std::exception& e) {
          errors[size_t(i)] = e.what();
        }
      },
      1);
  for (int i = 0; i < n; ++i)
    if (!errors[size_t(i)].empty()) throw Error("world " + std::to_string(i) + ": " + errors[size_t(i)]);
}

}  // namespace

struct Batch::Impl {
  std::vector<std::string> paths;
  std::vector<Options> options;
  std::vector<std::unique_ptr<Simulation>> worlds;
  std::vector<std::string> starts;  ///< each world's snapshot as it was made: reset restores it
  std::shared_ptr<rm3d::MeshCache> meshes = std::make_shared<rm3d::MeshCache>();  ///< parsed once for all
  std::unique_ptr<BehaviourPool> pool;
  std::shared_ptr<AgentArrays> arrays;
  int maxModules = 0;
  bool closed = false;

  void check() const {
    if (closed) throw Error("this batch is closed");
  }
  void bind(int i) {
    AgentArrays& a = *arrays;
    const size_t r0 = size_t(i) * size_t(maxModules);
    std::fill(a.mask.begin() + long(r0), a.mask.begin() + long(r0 + size_t(maxModules)), uint8_t(0));
    std::fill(a.obsSize.begin() + long(r0), a.obsSize.begin() + long(r0 + size_t(maxModules)), 0);
    std::fill(a.actSize.begin() + long(r0), a.actSize.begin() + long(r0 + size_t(maxModules)), 0);
    std::fill(a.obs.begin() + long(r0 * size_t(a.obsDim)),
              a.obs.begin() + long((r0 + size_t(maxModules)) * size_t(a.obsDim)), 0.0);
    worlds[size_t(i)]->bindArrays(arrays, int(r0), maxModules);
  }
  void open(int i) {
    auto w = Simulation::open(paths[size_t(i)], options[size_t(i)], meshes);
    w->arrays();  // the first read: sizes
    // The start reset() restores; a world that keeps no inputs (snapshots off) or records to a
    // file is opened again instead.
    if (options[size_t(i)].snapshots && options[size_t(i)].record.empty()) starts[size_t(i)] = w->snapshot();
    worlds[size_t(i)] = std::move(w);
  }
};

Batch::Batch(const std::vector<std::string>& paths, const std::vector<Options>& options, int threads)
    : m(std::make_unique<Impl>()) {
  if (paths.empty()) throw Error("Batch: no worlds (give at least one path)");
  if (paths.size() != options.size()) throw Error("Batch: one Options per world expected");
  if (threads < 1 || threads > 256)
    throw Error("threads=" + std::to_string(threads) + ": expected a whole number from 1 to 256");
  m->paths = paths;
  m->options = options;
  for (Options& o : m->options) o.threads = 1;  // the batch's threads step whole worlds
  m->pool = std::make_unique<BehaviourPool>(threads, 1);
  const int n = int(paths.size());
  m->worlds.resize(size_t(n));
  m->starts.resize(size_t(n));
  runAll(*m->pool, n, [this](int i) { m->open(i); });
  int obsDim = 0, actDim = 0;
  for (const auto& w : m->worlds) {
    m->maxModules = std::max(m->maxModules, w->moduleCount());
    obsDim = std::max(obsDim, w->obsDim());
    actDim = std::max(actDim, w->actDim());
  }
  auto a = std::make_shared<AgentArrays>();
  a->rows = n * m->maxModules;
  a->obsDim = obsDim;
  a->actDim = actDim;
  a->obs.assign(size_t(a->rows) * size_t(obsDim), 0.0);
  a->act.assign(size_t(a->rows) * size_t(actDim), 0.0);
  a->reward.assign(size_t(a->rows), 0.0);
  a->done.assign(size_t(a->rows), 0);
  a->mask.assign(size_t(a->rows), 0);
  a->obsSize.assign(size_t(a->rows), 0);
  a->actSize.assign(size_t(a->rows), 0);
  m->arrays = a;
  for (int i = 0; i < n; ++i) m->bind(i);
}

Batch::~Batch() = default;

int Batch::size() const {
  return int(m->paths.size());
}
int Batch::maxModules() const {
  return m->maxModules;
}

void Batch::step(int64_t n, const std::function<bool()>& interrupted) {
  m->check();
  if (n < 0) throw Error("step(n): n = " + std::to_string(n) + "; expected a whole number >= 0");
  // Rounds of 64 steps, so an interrupt is seen between them (every world at the same step).
  // Under policy one round: the arrays are read after a step() call, and its length stays the
  // caller's (a read is part of a snapshot's inputs).
  const int64_t round = m->options.front().policy || !interrupted ? n : 64;
  // Every world's actions checked before any world steps: an error leaves the batch in step
  // (world 0 used to step before world 1's NaN was found).
  if (n > 0 && m->options.front().policy)
    for (int i = 0; i < size(); ++i) {
      try {
        m->worlds[size_t(i)]->checkActions();
      } catch (const Error& e) {
        throw Error("world " + std::to_string(i) + ": " + e.what());
      }
    }
  for (int64_t done = 0; done < n;) {
    const int64_t k = std::min<int64_t>(round, n - done);
    runAll(*m->pool, size(), [this, k](int i) { m->worlds[size_t(i)]->step(k); });
    done += k;
    if (done < n && interrupted && interrupted()) break;
  }
}

void Batch::reset(const std::vector<uint8_t>& mask) {
  m->check();
  if (!mask.empty() && int(mask.size()) != size())
    throw Error("reset: the mask has " + std::to_string(mask.size()) + " entries; expected one per world (" +
                std::to_string(size()) + ")");
  std::vector<int> which;
  for (int i = 0; i < size(); ++i)
    if (mask.empty() || mask[size_t(i)]) which.push_back(i);
  // Each world restores its start snapshot: the texts it was made from, its meshes already parsed
  // (the Batch's cache), no file read again. About 5x faster than opening the file again.
  std::vector<std::unique_ptr<Simulation>> reopened(which.size());
  runAll(*m->pool, int(which.size()), [&](int k) {
    const int i = which[size_t(k)];
    if (!m->starts[size_t(i)].empty()) {
      m->worlds[size_t(i)]->restore(m->starts[size_t(i)]);
      return;
    }
    auto w = Simulation::open(m->paths[size_t(i)], m->options[size_t(i)], m->meshes);
    w->arrays();
    if (w->moduleCount() > m->maxModules || w->obsDim() > m->arrays->obsDim ||
        w->actDim() > m->arrays->actDim)
      throw Error(
          "reset: the world no longer fits the batch's arrays (more modules or longer rows than at the "
          "start)");
    reopened[size_t(k)] = std::move(w);
  });
  for (size_t k = 0; k < which.size(); ++k) {
    if (reopened[k]) m->worlds[size_t(which[k])] = std::move(reopened[k]);
    m->bind(which[k]);
  }
}

std::shared_ptr<AgentArrays> Batch::arrays() {
  m->check();
  runAll(*m->pool, size(), [this](int i) { m->worlds[size_t(i)]->arrays(); });
  return m->arrays;
}

Simulation& Batch::world(int i) {
  m->check();
  if (i < 0 || i >= size())
    throw Error("world " + std::to_string(i) + ": out of range (the batch has " + std::to_string(size()) +
                ")");
  return *m->worlds[size_t(i)];
}

void Batch::close() {
  if (m->closed) return;
  m->closed = true;
  for (auto& w : m->worlds)
    if (w) w->close();
}

std::vector<double> evaluate(const std::string& path, const std::vector<Options>& options, double seconds,
                             int threads, const std::string& metric, std::vector<std::string>* errors) {
  if (threads < 1 || threads > 256)
    throw Error("threads=" + std::to_string(threads) + ": expected a whole number from 1 to 256");
  if (!(seconds <= 1e9) || std::isnan(seconds))
    throw Error("seconds: expected a number of simulated seconds up to 1e9");
  if (metric.empty())
    throw Error("metric: empty; expected the name a world sets with world.metric(name, value)");
  const int n = int(options.size());
  std::vector<double> out(static_cast<size_t>(n), std::numeric_limits<double>::quiet_NaN());
  std::vector<std::string> errs(static_cast<size_t>(n));
  BehaviourPool pool(threads, 1);
  pool.run(
      n,
      [&](int i) {
        try {
          Options o = options[size_t(i)];
          o.threads = 1;
          o.policy = false;
          auto w = Simulation::open(path, o);
          if (seconds > 0) {
            w->step(std::llround(seconds / w->dt()));
          } else {
            while (!w->finished()) w->step(1);
          }
          w->finish();
          const auto ms = w->metrics();
          if (auto it = ms.find(metric); it != ms.end())
            out[size_t(i)] = it->second;
          else
            errs[size_t(i)] = "the run did not set the metric '" + metric + "' (world.metric)";
        } catch (const std::exception& e) {
          errs[size_t(i)] = e.what();
        }
      },
      1);
  if (errors) {
    errors->clear();
    for (int i = 0; i < n; ++i)
      if (!errs[size_t(i)].empty()) errors->push_back("run " + std::to_string(i) + ": " + errs[size_t(i)]);
  }
  return out;
}

}  // namespace rm3d::api
