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

void Watchdog::add(LuaVm* vm) {
  std::lock_guard<std::mutex> lock(m_mutex);
  m_entries.push_back(Entry{vm, vm->stamp(), 0.0, false});
}

void Watchdog::remove(LuaVm* vm) {
  std::lock_guard<std::mutex> lock(m_mutex);
  m_entries.erase(
      std::remove_if(m_entries.begin(), m_entries.end(), [vm](const Entry& e) { return e.vm == vm; }),
      m_entries.end());
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
    for (Entry& e : m_entries) {
      const uint64_t stamp = e.vm->stamp();
      const bool busy = e.vm->busy();
      if (!busy || stamp != e.stamp || e.vm->stamp() != stamp) {
        e.stamp = e.vm->stamp();
        e.busyFor = 0;
        e.fired = false;
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
