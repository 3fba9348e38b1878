// Items split among a run's tasks so that each task starts on the same items from one run to the
// next ("home ranges"), and helps with the others' once its own are done.
//
// A shared counter hands the next chunk to whichever thread asks first, so from one substep to the
// next a body, a pair or a solver batch goes to either thread, and its data must cross from the
// core that last wrote it. On a 2-core machine whose cores passed a cache line back and forth in
// 0.5 us, superbots_1000 took 32% more CPU time at 2 threads than at 1 (by perf), spread over
// every pass that touches the bodies. With home ranges each task takes chunks from the start of
// its own range first (task t: items [t n / T, (t + 1) n / T), rounded up), so an item goes to the same
// thread while the scene stays as it is; a task whose range is done takes chunks from the others' in turn (a
// busy core does not hold the run up). Which task runs an item changes nothing in the results.
#pragma once

#include <algorithm>
#include <atomic>
#include <memory>

namespace rm3d {

class HomeRanges {
 public:
  /// Before a run (on the calling thread): n items, `tasks` tasks, taken `chunk` at a time.
  void begin(int n, int tasks, int chunk) {
    tasks = std::max(1, tasks);
    if (tasks > m_capacity) {
      m_ranges = std::make_unique<Range[]>(size_t(tasks));
      m_capacity = tasks;
    }
    m_tasks = tasks;
    m_chunk = std::max(1, chunk);
    // Range t starts at n t / T; with fewer items than tasks, item i is task i's.
    auto start = [&](int t) { return n < tasks ? std::min(t, n) : int(int64_t(n) * t / tasks); };
    for (int t = 0; t < tasks; ++t) {
      m_ranges[size_t(t)].next.store(start(t), std::memory_order_relaxed);
      m_ranges[size_t(t)].end = start(t + 1);
    }
  }

  /// fn(i) for every i in [0, n), as `count` tasks handed to tasks(count, task) (a pool's run of
  /// one task a thread, task t on the t-th thread), `chunk` items at a time.
  template <class Tasks, class Fn>
  void forEach(const Tasks& tasks, int count, int n, int chunk, const Fn& fn) {
    begin(n, count, chunk);
    tasks(count, [&](int t) {
      run(t, [&](int b, int e) {
        for (int i = b; i < e; ++i) fn(i);
      });
    });
  }

  /// Task t's share: fn(begin, end) for each chunk it takes, its own range's first.
  template <class Fn>
  void run(int t, const Fn& fn) {
    for (int k = 0; k < m_tasks; ++k) {
      Range& r = m_ranges[size_t((t + k) % m_tasks)];
      for (int b = r.next.fetch_add(m_chunk, std::memory_order_relaxed); b < r.end;
           b = r.next.fetch_add(m_chunk, std::memory_order_relaxed))
        fn(b, std::min(r.end, b + m_chunk));
    }
  }

 private:
  struct alignas(64) Range {  // (a cache line of its own: its task takes from it chunk by chunk)
    std::atomic<int> next{0};
    int end = 0;
  };
  std::unique_ptr<Range[]> m_ranges;
  int m_capacity = 0;
  int m_tasks = 1;
  int m_chunk = 1;
};

}  // namespace rm3d
