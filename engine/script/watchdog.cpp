// The watchdog thread: samples each VM's call stamp; a stamp that stays the same while the VM
// is busy for longer than the limit means one call has run that long.
#include "script/watchdog.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>

#include "script/lua_vm.h"

namespace rm3d {

Watchdog::Watchdog(double seconds) : m_seconds(seconds) {
  m_thread = std::thread([this] { run(); });
}

Watchdog::~Watchdog() {
  {
    std::lock_guard<std::mutex> lock(m_mutex);
    m_stop = true;
  }
  m_wake.notify_all();
  m_thread.join();
}

WatchSlot* Watchdog::add(LuaVm* vm, uint64_t stamp, int& index) {
  std::lock_guard<std::mutex> lock(m_mutex);
  if (!m_free.empty()) {
    index = m_free.back();
    m_free.pop_back();
  } else {
    index = int(m_entries.size());
    if (index % kChunk == 0) m_slots.push_back(std::make_unique<WatchSlot[]>(kChunk));
    m_entries.push_back(Entry{});
  }
  WatchSlot& s = slot(index);
  s.stamp.store(stamp, std::memory_order_relaxed);
  s.busy.store(false, std::memory_order_relaxed);
  m_entries[size_t(index)] = Entry{vm, stamp, 0.0, false};
  return &s;
}

void Watchdog::remove(int index) {
  std::lock_guard<std::mutex> lock(m_mutex);
  m_entries[size_t(index)].vm = nullptr;
  m_free.push_back(index);
}

void Watchdog::run() {
  using Clock = std::chrono::steady_clock;
  const auto tick = std::chrono::duration<double>(std::clamp(m_seconds / 20, 0.005, 0.1));
  const double grace = std::max(1.0, m_seconds);
  std::unique_lock<std::mutex> lock(m_mutex);
  auto last = Clock::now();
  while (!m_stop) {
    m_wake.wait_for(lock, tick);
    if (m_stop) break;
    const auto now = Clock::now();
    const double elapsed = std::chrono::duration<double>(now - last).count();
    last = now;
    for (size_t i = 0; i < m_entries.size(); ++i) {
      Entry& e = m_entries[i];
      if (!e.vm) continue;
      const WatchSlot& s = slot(int(i));
      const uint64_t stamp = s.stamp.load(std::memory_order_relaxed);
      const bool busy = s.busy.load(std::memory_order_relaxed);
      if (!busy || stamp != e.stamp || s.stamp.load(std::memory_order_relaxed) != stamp) {
        const uint64_t last = s.stamp.load(std::memory_order_relaxed);
        if (e.busyFor != 0 || e.fired || e.stamp != last) e = Entry{e.vm, last, 0.0, false};
        continue;
      }
      e.busyFor += elapsed;
      if (!e.fired && e.busyFor >= m_seconds) {
        e.fired = true;
        e.vm->interrupt(stamp, m_seconds);
      } else if (e.fired && e.busyFor >= m_seconds + grace) {
        const char* what = e.vm->currentCall();
        std::fprintf(stderr,
                     "rm3d: watchdog: %s of %s did not return within %g s and did not stop when interrupted "
                     "%g s later (stuck outside Lua code); exiting with code %d\n",
                     what ? what : "a call", e.vm->name().empty() ? "a Lua VM" : e.vm->name().c_str(),
                     m_seconds, grace, kWatchdogExitCode);
        std::fflush(stderr);
        std::_Exit(kWatchdogExitCode);
      }
    }
  }
}

}  // namespace rm3d
