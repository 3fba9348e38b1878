// One sandboxed Lua 5.4 state: a memory cap, an instruction budget per call, a restricted
// standard library, `require` limited to the project's Lua folders, and one protected call
// path with a traceback (lua.c's docall/msghandler).
//
// Limits (each ends a call with an ordinary Lua error carrying file:line and a traceback):
// - Instruction budget: a count hook every kHookInterval instructions adds to one counter per
//   VM, so coroutines share the budget. Once a call is over its budget (or interrupted by the
//   watchdog, or over its memory cap) the VM is "aborting": the hook is re-armed to fire on
//   every instruction and raises again, so pcall/xpcall cannot swallow it, until control is
//   back in the host.
// - Memory: the cap is soft. The first allocation over it succeeds and makes the next
//   instruction raise "out of memory: ..."; only past 1.25x the cap does the allocator fail
//   (then Lua reports a plain memory error). Outside calls (host pushes) nothing fails.
// - Wall clock: a Watchdog (script/watchdog.h) interrupts a call that does not return within
//   its limit.
// - Finalizers: Lua runs __gc with hooks disabled, so no limit could stop an endless one;
//   setmetatable refuses metatables with a __gc field.
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "core/text_file.h"
#include "script/vm_heap.h"
#include "script/watchdog.h"

struct lua_State;
struct lua_Debug;

namespace rm3d {

class SourceFiles;

class LuaVm {
 public:
  static constexpr int kHookInterval = 1000;

  /// memoryLimit in bytes (0: none).
  explicit LuaVm(size_t memoryLimit = 0);
  ~LuaVm();
  LuaVm(const LuaVm&) = delete;
  LuaVm& operator=(const LuaVm&) = delete;

  lua_State* L() const { return m_L; }
  /// Where the state's address is kept (to fetch it ahead: Behaviour::fetchState).
  const void* stateSlot() const { return &m_L; }

  /// Folders `require` searches, in order (absolute paths).
  void setRequirePath(std::vector<std::string> dirs) { m_requirePath = std::move(dirs); }
  const std::vector<std::string>& requirePath() const { return m_requirePath; }
  /// Instructions one protected call may run before it is stopped (0: no limit).
  void setInstructionBudget(int64_t n) { m_budget = n; }
  /// Root that chunk names are shown relative to ("behaviors/snake.lua:12:").
  void setDisplayRoot(std::string root) { m_displayRoot = std::move(root); }
  /// Who owns the VM, for messages: "module" (default) or "world script".
  void setOwnerLabel(std::string label) { m_owner = std::move(label); }
  /// A name for the VM in watchdog messages ("module snake_3").
  void setName(std::string name) { m_name = std::move(name); }
  const std::string& name() const { return m_name; }
  /// Reads sources through these (a recording's texts, or noting what is read); nullptr: the disk.
  void setSources(SourceFiles* s) { m_sources = s; }
  /// Registers with a watchdog (nullptr: none). The watchdog must outlive the VM or be unset.
  void setWatchdog(Watchdog* w);

  /// Loads a file as a text chunk and leaves the function on the stack.
  bool loadFile(const std::string& path, std::string& err);
  /// Calls the function below nargs arguments, with the instruction budget and a traceback
  /// on error. On failure pops everything it pushed and sets err ("file:line: message\n...").
  /// `what` names the call in watchdog messages ("step()").
  bool call(int nargs, int nresults, std::string& err, const char* what = nullptr);
  /// loadFile + call.
  bool runFile(const std::string& path, int nresults, std::string& err);
  /// Runs f(L) as a protected call (with the budget and traceback): for host code that looks
  /// into the VM (metamethods may run, allocation may fail). `ud` is f's first argument as a
  /// light userdata; f's results stay on the stack (nresults).
  bool protect(int (*f)(lua_State*), void* ud, int nresults, std::string& err, const char* what = nullptr);

  size_t memoryUsed() const { return m_used; }
  size_t memoryLimit() const { return m_limit; }
  std::string displayName(const std::string& path) const;

  /// Charges n instructions' worth of work done in C (pattern matching) to the current call;
  /// raises the budget (or watchdog) error when over. Only from inside a call on this VM.
  /// `what` names the work in the budget message ("pattern matching").
  static void charge(lua_State* L, int64_t n, const char* what = nullptr);

  /// The LuaVm that owns a state (stored in the state's extra space slot next to the user slot).
  static LuaVm* from(lua_State* L);
  /// Raises "out of memory: WHAT would take N bytes, more than the memory cap (M MiB) leaves room
  /// for" (a Lua error, so it carries file:line) when `bytes` do not fit under the VM's cap:
  /// called before anything large is built on a script's behalf (string.rep, linalg matrices,
  /// particle position tables).
  static void checkRoom(lua_State* L, double bytes, const char* what);
  /// A per-state pointer for bindings (the module or world context).
  void setUser(void* p) { m_user = p; }
  void* user() const { return m_user; }

  // For the watchdog (read from its thread).
  /// Changes at every call begin and end and when a nested call on another VM starts or ends.
  uint64_t stamp() const { return m_slot->stamp.load(std::memory_order_relaxed); }
  /// True while an outermost call runs and no nested call of another VM runs under it.
  bool busy() const { return m_slot->busy.load(std::memory_order_relaxed); }
  /// Asks the call identified by `stamp` to stop (no effect if it has returned meanwhile).
  void interrupt(uint64_t stamp, double seconds);
  /// A limit tripped in the current call (every further instruction raises).
  bool aborting() const { return m_abort != Abort::None; }
  const char* currentCall() const { return m_what.load(std::memory_order_relaxed); }
  /// Calls on this VM the watchdog has stopped so far (read once the calls are over).
  int watchdogStops() const { return m_watchdogStops; }

 private:
  enum class Abort : uint8_t { None, Budget, Watchdog, Memory };
  static void* alloc(void* ud, void* ptr, size_t osize, size_t nsize);
  static int require(lua_State* L);
  static int panic(lua_State* L);
  static void hook(lua_State* L, lua_Debug* ar);
  [[noreturn]] static void raiseAbort(lua_State* L, int level);
  std::string abortMessage() const;
  void abort(lua_State* L, Abort why);
  void noteWatchdogStop();
  void openSandbox();
  void beginCall(const char* what);
  void endCall();
  /// A new stamp, and busy or not (beginCall, endCall).
  void publish(bool busy);

  VmHeap m_heap;  ///< the state's memory (declared before m_L: lua_close gives it all back first)
  lua_State* m_L = nullptr;
  size_t m_limit = 0;
  size_t m_used = 0;
  int64_t m_budget = 0;
  int64_t m_count = 0;  ///< instructions run in the current outermost call
  int m_depth = 0;      ///< nesting of call() on this VM
  Abort m_abort = Abort::None;
  const char* m_abortWhat = nullptr;  ///< C work that spent the budget (charge's `what`)
  bool m_memArmed = false;            ///< over the soft cap since it was last below
  int m_watchdogStops = 0;            ///< calls ended by the watchdog (m_abort was Watchdog)
  void* m_user = nullptr;
  Watchdog* m_watchdog = nullptr;
  SourceFiles* m_sources = nullptr;
  LuaVm* m_outer = nullptr;        ///< the VM whose call this thread was in when ours began
  WatchSlot m_ownSlot;             ///< the stamp and busy flag while no watchdog watches
  WatchSlot* m_slot = &m_ownSlot;  ///< where they are now (the watchdog's slot while it watches)
  int m_slotIndex = -1;            ///< the watchdog's number for m_slot
  std::atomic<uint64_t> m_interruptStamp{~uint64_t(0)};
  std::atomic<double> m_interruptSeconds{0};
  std::atomic<const char*> m_what{nullptr};
  std::vector<std::string> m_requirePath;
  std::string m_displayRoot;
  std::string m_owner = "module";
  std::string m_name;
};

/// Seals the metatable on the top of the stack: getmetatable on a handle returns false, and
/// setmetatable refuses it, so no script can add __gc (or any other metamethod) to a handle type.
/// Every handle type (Body, Module, Cloth, Heightfield, Particles, Joint, Dock, linalg) uses it.
void sealMetatable(lua_State* L);

/// Replaces bytes that are not valid UTF-8 with '?' (fault texts end up in JSON and logs).
void makeValidUtf8(std::string& s);

/// Installs our bounded pattern matcher as string.find/match/gmatch/gsub (lua_patterns.cpp).
void openBoundedPatterns(lua_State* L);

}  // namespace rm3d
