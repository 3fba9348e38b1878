// A small fork-join pool: the caller and the workers take chunks of module indices from an
// atomic counter until none are left.
#include "world/behaviour_pool.h"

namespace rm3d {

BehaviourPool::BehaviourPool(int threads, int chunk) : m_chunk(chunk < 1 ? 1 : chunk) {
  for (int i = 1; i < threads; ++i) m_workers.emplace_back([this] { work(); });
}

BehaviourPool::~BehaviourPool() {
  {
    std::lock_guard<std::mutex> lock(m_mutex);
    m_quit = true;
  }
  m_wake.notify_all();
  for (std::thread& t : m_workers) t.join();
}

void BehaviourPool::drain() {
  for (;;) {
    const int begin = m_next.fetch_add(m_runChunk);
    if (begin >= m_n) return;
    const int end = begin + m_runChunk < m_n ? begin + m_runChunk : m_n;
    for (int i = begin; i < end; ++i) (*m_fn)(i);
  }
}

void BehaviourPool::run(int n, const std::function<void(int)>& fn, int chunk) {
  const int c = chunk > 0 ? chunk : m_chunk;
  if (m_workers.empty() || n <= c) {
    for (int i = 0; i < n; ++i) fn(i);
    return;
  }
  {
    std::lock_guard<std::mutex> lock(m_mutex);
    m_fn = &fn;
    m_n = n;
    m_runChunk = c;
    m_next.store(0);
    m_busy = int(m_workers.size());
    ++m_generation;
  }
  m_wake.notify_all();
  drain();
  std::unique_lock<std::mutex> lock(m_mutex);
  m_done.wait(lock, [this] { return m_busy == 0; });
  m_fn = nullptr;
}

void BehaviourPool::work() {
  uint64_t seen = 0;
  for (;;) {
    {
      std::unique_lock<std::mutex> lock(m_mutex);
      m_wake.wait(lock, [&] { return m_quit || m_generation != seen; });
      if (m_quit) return;
      seen = m_generation;
    }
    drain();
    {
      std::lock_guard<std::mutex> lock(m_mutex);
      if (--m_busy == 0) m_done.notify_one();
    }
  }
}

}  // namespace rm3d
