// A small fork-join pool: the caller and the workers take chunks of indices, each from its own
// range first (core/home_ranges.h), until none are left.
#include "world/behaviour_pool.h"

#include <chrono>

namespace rm3d {

namespace {

inline void cpuRelax() {
#if defined(__x86_64__) || defined(__i386__)
  __builtin_ia32_pause();
#endif
}

}  // namespace

BehaviourPool::BehaviourPool(int threads, int chunk) : m_chunk(chunk < 1 ? 1 : chunk) {
  const unsigned cores = std::thread::hardware_concurrency();
  m_watch = threads > 1 && cores > 0 && unsigned(threads) <= cores;
  for (int i = 1; i < threads; ++i) m_workers.emplace_back([this, i] { work(i); });
}

BehaviourPool::~BehaviourPool() {
  {
    std::lock_guard<std::mutex> lock(m_mutex);
    m_quit.store(true);
  }
  m_wake.notify_all();
  for (std::thread& t : m_workers) t.join();
}

template <class Done>
void BehaviourPool::await(std::condition_variable& cv, const Done& done) {
  if (m_watch) {
    constexpr int kPausesPerLook = 64;  // pauses between looks at the clock
    const auto until = std::chrono::steady_clock::now() + kWatch;
    for (int i = 1;; ++i) {
      if (done()) return;
      if (i % kPausesPerLook == 0 && !m_hold.load(std::memory_order_relaxed) &&
          std::chrono::steady_clock::now() > until)
        break;
      cpuRelax();
    }
  }
  std::unique_lock<std::mutex> lock(m_mutex);
  cv.wait(lock, done);
}

void BehaviourPool::drain(int self) {
  m_homes.run(self, [this](int begin, int end) {
    for (int i = begin; i < end; ++i) m_fn(i);
  });
}

void BehaviourPool::run(int n, FunctionRef<void(int)> fn, int chunk) {
  const int c = chunk > 0 ? chunk : m_chunk;
  if (m_workers.empty() || n <= c) {
    for (int i = 0; i < n; ++i) fn(i);
    return;
  }
  {
    std::lock_guard<std::mutex> lock(m_mutex);
    m_fn = fn;
    m_homes.begin(n, threads(), c);
    m_busy.store(int(m_workers.size()));
    m_generation.fetch_add(1, std::memory_order_release);  // (the run's fields are set before)
  }
  m_wake.notify_all();
  drain(0);
  await(m_done, [this] { return m_busy.load(std::memory_order_acquire) == 0; });
  m_fn = {};
}

void BehaviourPool::work(int self) {
  uint64_t seen = 0;
  for (;;) {
    await(m_wake, [&] { return m_quit.load() || m_generation.load(std::memory_order_acquire) != seen; });
    if (m_quit.load()) return;
    seen = m_generation.load(std::memory_order_acquire);
    drain(self);
    if (m_busy.fetch_sub(1, std::memory_order_acq_rel) == 1) {
      std::lock_guard<std::mutex> lock(m_mutex);  // (the caller may be between its check and its wait)
      m_done.notify_one();
    }
  }
}

}  // namespace rm3d
