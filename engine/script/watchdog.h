// Wall-clock limit on calls into Lua VMs: one thread per World samples the VMs registered with
// it; a call that has not returned within the limit is interrupted (its next count hook, or the
// pattern matcher's next charge, raises "watchdog: step() did not return within S s"). A call
// that still has not returned after a grace period is stuck in C code: the process ends with a
// message on stderr and exit code 3 (kWatchdogExitCode).
//
// What the thread samples, each VM's call stamp and busy flag, lies in the watchdog's own slots,
// side by side, not in the VMs: a tick reads every registered VM, and read from 10,000 VMs
// scattered over memory that cost a cache miss each, about 4 ms of CPU a step at 10,000 modules
// (the thread ticks at a fixed rate, so its cost a step grew as the square of the modules).
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <memory>
#include <mutex>
#include <thread>
#include <vector>

namespace rm3d {

class LuaVm;

inline constexpr int kWatchdogExitCode = 3;

/// What a VM's calls publish for the watchdog (written by the calling thread, read by the
/// watchdog's).
struct WatchSlot {
  /// Changes at every call begin and end and when a nested call on another VM starts or ends.
  std::atomic<uint64_t> stamp{0};
  /// True while an outermost call runs and no nested call of another VM runs under it.
  std::atomic<bool> busy{false};
};

class Watchdog {
 public:
  /// seconds > 0: the limit on one call.
  explicit Watchdog(double seconds);
  ~Watchdog();
  Watchdog(const Watchdog&) = delete;
  Watchdog& operator=(const Watchdog&) = delete;

  double seconds() const { return m_seconds; }
  /// Registers a VM (not in a call); its slot starts at `stamp`. The slot stays valid until
  /// remove(index); `index` receives the slot's number.
  WatchSlot* add(LuaVm* vm, uint64_t stamp, int& index);
  void remove(int index);
  /// Calls the watchdog actually stopped (an interrupted call that returned first does not
  /// count), over every VM registered with it. LuaVm reports each stop.
  int stops() const { return m_stops.load(std::memory_order_relaxed); }
  void noteStop() { m_stops.fetch_add(1, std::memory_order_relaxed); }

 private:
  static constexpr int kChunk = 1024;  ///< slots per block (blocks never move)
  struct Entry {                       ///< the watchdog thread's own view of a slot
    LuaVm* vm;                         ///< null: the slot is free
    uint64_t stamp;
    double busyFor;
    bool fired;
  };
  WatchSlot& slot(int i) { return m_slots[size_t(i / kChunk)][size_t(i % kChunk)]; }
  void run();

  double m_seconds;
  std::mutex m_mutex;
  std::condition_variable m_wake;
  bool m_stop = false;
  std::vector<std::unique_ptr<WatchSlot[]>> m_slots;
  std::vector<Entry> m_entries;  ///< one per slot
  std::vector<int> m_free;       ///< removed slots, reused first
  std::atomic<int> m_stops{0};
  std::thread m_thread;
};

}  // namespace rm3d
