// The step allocates nothing of its own once warm: this program replaces the global operator new
// (and its array, aligned and nothrow forms), builds worlds like `rm3d bench`'s scenes (a crawling
// snake of SuperBots, separate SuperBots moving every motor, spinning ATRONs), steps each 120 steps
// to warm its buffers, then counts the calls to operator new in the next 120 steps (up to eight
// such windows, the fewest counting), at 1 and 2 threads. A buffer that grows to a new high-water mark (more
// contacts than ever before) may call it now and then; a call in every step fails: the count must stay under
// one call in ten steps.
//
// What this sees: every std::vector, std::string and std::function (over 16 bytes) that grows or
// is made in a step, on any thread. What it does not see: Lua's allocations (lua_Alloc, realloc)
// and Bullet's own (btAlignedAlloc, malloc), among them the compound-pair caches Bullet makes and
// frees as bounding boxes start and stop overlapping (see docs/benchmarks.md, "No allocation in a
// step"). To see where a call comes from: RM3D_TRAP_ALLOCATION=1 gdb -batch -ex run -ex bt
// build/rm3d_step_allocations (the first counted call aborts; =N, the N-th).
#include <algorithm>
#include <atomic>
#include <cstddef>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <new>
#include <string>

#include "world/world.h"

namespace {

std::atomic<bool> g_counting{false};
std::atomic<long> g_calls{0};

void* allocate(std::size_t size, std::size_t align) {
  if (g_counting.load(std::memory_order_relaxed)) {
    const long n = g_calls.fetch_add(1, std::memory_order_relaxed);
    // (RM3D_TRAP_ALLOCATION=N: the N-th counted call aborts, so that a debugger shows where.)
    if (const char* t = std::getenv("RM3D_TRAP_ALLOCATION"); t && n + 1 >= std::max(1L, std::atol(t)))
      std::abort();  // a debugger shows where
  }
  if (size == 0) size = 1;
  void* p = align > alignof(std::max_align_t) ? std::aligned_alloc(align, (size + align - 1) / align * align)
                                              : std::malloc(size);
  return p;
}

}  // namespace

void* operator new(std::size_t size) {
  if (void* p = allocate(size, 0)) return p;
  throw std::bad_alloc();
}
void* operator new[](std::size_t size) {
  if (void* p = allocate(size, 0)) return p;
  throw std::bad_alloc();
}
void* operator new(std::size_t size, std::align_val_t align) {
  if (void* p = allocate(size, static_cast<std::size_t>(align))) return p;
  throw std::bad_alloc();
}
void* operator new[](std::size_t size, std::align_val_t align) {
  if (void* p = allocate(size, static_cast<std::size_t>(align))) return p;
  throw std::bad_alloc();
}
void* operator new(std::size_t size, const std::nothrow_t&) noexcept {
  return allocate(size, 0);
}
void* operator new[](std::size_t size, const std::nothrow_t&) noexcept {
  return allocate(size, 0);
}
void* operator new(std::size_t size, std::align_val_t align, const std::nothrow_t&) noexcept {
  return allocate(size, static_cast<std::size_t>(align));
}
void* operator new[](std::size_t size, std::align_val_t align, const std::nothrow_t&) noexcept {
  return allocate(size, static_cast<std::size_t>(align));
}
void operator delete(void* p) noexcept {
  std::free(p);
}
void operator delete[](void* p) noexcept {
  std::free(p);
}
void operator delete(void* p, std::size_t) noexcept {
  std::free(p);
}
void operator delete[](void* p, std::size_t) noexcept {
  std::free(p);
}
void operator delete(void* p, std::align_val_t) noexcept {
  std::free(p);
}
void operator delete[](void* p, std::align_val_t) noexcept {
  std::free(p);
}
void operator delete(void* p, std::size_t, std::align_val_t) noexcept {
  std::free(p);
}
void operator delete[](void* p, std::size_t, std::align_val_t) noexcept {
  std::free(p);
}

namespace {

struct Scene {
  const char* name;
  const char* script;
};

const Scene kScenes[] = {
    {"snake_100", R"(world.set{duration = 1e9}
world.ground{}
require("snake_chain").build{n = 100, type = "superbot", behavior = "behaviors/snake.lua"})"},
    {"superbots_64", R"(world.set{duration = 1e9}
world.ground{}
for i = 0, 63 do
  world.spawn("superbot", {at = {(i % 8) * 0.35, (i // 8) * 0.30, 0.043}, behavior = "behaviors/alternate.lua"})
end)"},
    {"atrons_64", R"(world.set{duration = 1e9}
world.ground{}
for i = 0, 63 do
  world.spawn("atron", {at = {(i % 8) * 0.16, (i // 8) * 0.16, 0.056}, behavior = "behaviors/atron_wheel.lua",
                        params = {speed = 1}})
end)"},
};

constexpr int kWarmSteps = 120;
constexpr int kCountedSteps = 120;
constexpr long kMostCalls = kCountedSteps / 10 - 1;
constexpr int kWindows = 8;

}  // namespace

int main() {
  int failed = 0, passed = 0;
  for (const Scene& scene : kScenes) {
    for (int threads : {1, 2}) {
      long calls = -1;
      std::string error;
      try {
        rm3d::RunOptions o;
        o.projectRoot = RM3D_SOURCE_DIR;
        o.echoLog = false;
        o.threads = threads;
        rm3d::World w(o);
        w.loadString(scene.script, std::string(scene.name) + ".lua");
        for (int i = 0; i < kWarmSteps; ++i) w.step();
        // Up to kWindows windows, the fewest calls counting: an allocation in every step shows in
        // each, while a buffer's new high-water mark is made once. (With a core kept busy by
        // another process, the other thread took more island batches in one substep than ever
        // before, and its solver's buffers grew inside the window: 12 to 106 calls in 120 steps; with
        // three windows the fewest was still 12 in 5 of 10 runs. Eight, in 10 runs with a busy core: 0
        // fails.)
        for (int window = 0; window < kWindows && (calls < 0 || calls > kMostCalls); ++window) {
          g_calls = 0;
          g_counting = true;
          for (int i = 0; i < kCountedSteps; ++i) w.step();
          g_counting = false;
          calls = calls < 0 ? g_calls.load() : std::min(calls, g_calls.load());
        }
        if (w.faultCount() != 0) error = std::to_string(w.faultCount()) + " modules faulted";
      } catch (const std::exception& e) {
        g_counting = false;
        error = e.what();
      }
      const bool ok = error.empty() && calls >= 0 && calls <= kMostCalls;
      std::printf("%s %s at %d thread%s: %ld calls to operator new in %d steps (at most %ld)%s%s\n",
                  ok ? "ok  " : "FAIL", scene.name, threads, threads == 1 ? "" : "s", calls, kCountedSteps,
                  kMostCalls, error.empty() ? "" : ": ", error.c_str());
      ok ? ++passed : ++failed;
    }
  }
  std::printf("%d passed, %d failed\n", passed, failed);
  return failed == 0 ? 0 : 1;
}
