// Worker threads for the behaviour phase. Each module's VM is independent and writes only its
// own buffers, so running them in any order or in parallel gives identical results.
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

#include "core/function_ref.h"
#include "core/home_ranges.h"

namespace rm3d {

class BehaviourPool {
 public:
  /// threads: total, including the calling thread (1: run inline); chunk: indices a thread
  /// takes at a time (a run of `chunk` or fewer indices stays on the calling thread).
  BehaviourPool(int threads, int chunk = 16);
  ~BehaviourPool();
  BehaviourPool(const BehaviourPool&) = delete;
  BehaviourPool& operator=(const BehaviourPool&) = delete;

  /// Calls fn(i) for every i in [0, n) and returns when all calls are done; `chunk` > 0 overrides
  /// the pool's chunk for this call (1: each index taken alone, for n coarse blocks of work; with
  /// no more indices than threads, index k starts on the k-th thread: 0 on the caller).
  void run(int n, FunctionRef<void(int)> fn, int chunk = 0);
  int threads() const { return int(m_workers.size()) + 1; }
  /// Whether waiting threads watch before they sleep: more than one thread, no more than cores.
  bool watches() const { return m_watch; }
  /// While held (a step in progress), threads that wait for the next run or for the workers watch
  /// for it without the kWatch limit, where the pool watches at all: a step's runs come up to a
  /// few milliseconds apart, and a worker that had gone to sleep started its share of the next
  /// one about 0.1 ms late on a virtual machine (the narrowphase of `snake_1000`, 4 of a step's 5
  /// runs). Released, they sleep after kWatch as before (between steps, a caller may do anything).
  void hold(bool on) { m_hold.store(on, std::memory_order_relaxed); }

  /// A step hands the pool several runs (behaviours, contacts, bodies, solver batches) a few
  /// hundred microseconds apart or less; a thread woken from sleep took tens of microseconds to
  /// start. So a worker that has finished a run, and the caller waiting for the workers, watch
  /// for the next event this long before they sleep; not where there are more threads than cores
  /// (a watching thread would take the core of one with work).
  static constexpr auto kWatch = std::chrono::microseconds(200);

 private:
  void work(int self);
  /// The calling thread's share of the run; `self`: 0 for the caller, k for the k-th worker.
  void drain(int self);
  /// Waits until done() is true: watching for kWatch where the pool may, then on `cv`.
  template <class Done>
  void await(std::condition_variable& cv, const Done& done);

  std::vector<std::thread> m_workers;
  std::mutex m_mutex;
  std::condition_variable m_wake, m_done;
  FunctionRef<void(int)> m_fn;  // the run's (set while it runs)
  int m_chunk = 16;
  bool m_watch = false;  // fewer threads than cores: waits watch a while first
  // The run's indices, a range per thread: a module's VM stays on one core from run to run, and in
  // a run of one task a thread (chunk 1, no more tasks than threads) the k-th thread starts with
  // task k, so the data a task keeps (a thread's solver, its share of the bodies) stays in that
  // core's cache; a thread done with its own takes what another has not started.
  HomeRanges m_homes;
  std::atomic<int> m_busy{0};
  std::atomic<uint64_t> m_generation{0};
  std::atomic<bool> m_quit{false};
  std::atomic<bool> m_hold{false};
};

}  // namespace rm3d
