// One sandboxed Lua 5.4 state: a memory cap, an instruction budget per call, a restricted
// standard library, `require` limited to the project's Lua folders, and one protected call
// path with a traceback (lua.c's docall/msghandler).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

struct lua_State;

namespace rm3d {

class LuaVm {
 public:
  /// memoryLimit in bytes (0: none).
  explicit LuaVm(size_t memoryLimit = 0);
  ~LuaVm();
  LuaVm(const LuaVm&) = delete;
  LuaVm& operator=(const LuaVm&) = delete;

  lua_State* L() const { return m_L; }

  /// Folders `require` searches, in order (absolute paths).
  void setRequirePath(std::vector<std::string> dirs) { m_requirePath = std::move(dirs); }
  const std::vector<std::string>& requirePath() const { return m_requirePath; }
  /// Instructions one protected call may run before it is stopped (0: no limit).
  void setInstructionBudget(int64_t n) { m_budget = n; }
  /// Root that chunk names are shown relative to ("behaviors/snake.lua:12:").
  void setDisplayRoot(std::string root) { m_displayRoot = std::move(root); }

  /// Loads a file as a text chunk and leaves the function on the stack.
  bool loadFile(const std::string& path, std::string& err);
  /// Calls the function below nargs arguments, with the instruction budget and a traceback
  /// on error. On failure pops everything it pushed and sets err ("file:line: message\n...").
  bool call(int nargs, int nresults, std::string& err);
  /// loadFile + call.
  bool runFile(const std::string& path, int nresults, std::string& err);

  size_t memoryUsed() const { return m_used; }
  std::string displayName(const std::string& path) const;

  /// The LuaVm that owns a state (stored in the state's extra space slot next to the user slot).
  static LuaVm* from(lua_State* L);
  /// A per-state pointer for bindings (the module or world context).
  void setUser(void* p) { m_user = p; }
  void* user() const { return m_user; }

 private:
  static void* alloc(void* ud, void* ptr, size_t osize, size_t nsize);
  static int require(lua_State* L);
  void openSandbox();

  lua_State* m_L = nullptr;
  size_t m_limit = 0;
  size_t m_used = 0;
  int64_t m_budget = 0;
  void* m_user = nullptr;
  std::vector<std::string> m_requirePath;
  std::string m_displayRoot;
};

/// Reads a file into a string; false if it cannot be read.
bool readTextFile(const std::string& path, std::string& out);

}  // namespace rm3d
