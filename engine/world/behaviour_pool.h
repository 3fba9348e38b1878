// Worker threads for the behaviour phase. Each module's VM is independent and writes only its
// own buffers, so running them in any order or in parallel gives identical results.
#pragma once

#include <atomic>
#include <condition_variable>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

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
  /// the pool's chunk for this call (1: each index taken alone, for n coarse blocks of work).
  void run(int n, const std::function<void(int)>& fn, int chunk = 0);
  int threads() const { return int(m_workers.size()) + 1; }

 private:
  void work();
  void drain();

  std::vector<std::thread> m_workers;
  std::mutex m_mutex;
  std::condition_variable m_wake, m_done;
  const std::function<void(int)>* m_fn = nullptr;
  int m_n = 0;
  int m_chunk = 16;
  int m_runChunk = 16;  // the chunk of the run under way
  std::atomic<int> m_next{0};
  int m_busy = 0;
  uint64_t m_generation = 0;
  bool m_quit = false;
};

}  // namespace rm3d
