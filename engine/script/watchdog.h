// Wall-clock limit on calls into Lua VMs: one thread per World samples the VMs registered with
// it; a call that has not returned within the limit is interrupted (its next count hook, or the
// pattern matcher's next charge, raises "watchdog: step() did not return within S s"). A call
// that still has not returned after a grace period is stuck in C code: the process ends with a
// message on stderr and exit code 3 (kWatchdogExitCode).
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <thread>
#include <vector>

namespace rm3d {

class LuaVm;

inline constexpr int kWatchdogExitCode = 3;

class Watchdog {
 public:
  /// seconds > 0: the limit on one call.
  explicit Watchdog(double seconds);
  ~Watchdog();
  Watchdog(const Watchdog&) = delete;
  Watchdog& operator=(const Watchdog&) = delete;

  double seconds() const { return m_seconds; }
  void add(LuaVm* vm);
  void remove(LuaVm* vm);
  /// Calls the watchdog actually stopped (an interrupted call that returned first does not
  /// count), over every VM registered with it. LuaVm reports each stop.
  int stops() const { return m_stops.load(std::memory_order_relaxed); }
  void noteStop() { m_stops.fetch_add(1, std::memory_order_relaxed); }

 private:
  struct Entry {
    LuaVm* vm;
    uint64_t stamp;
    double busyFor;
    bool fired;
  };
  void run();

  double m_seconds;
  std::mutex m_mutex;
  std::condition_variable m_wake;
  bool m_stop = false;
  std::vector<Entry> m_entries;
  std::atomic<int> m_stops{0};
  std::thread m_thread;
};

}  // namespace rm3d
