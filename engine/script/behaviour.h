// A module's behaviour: its VM with the behaviour API installed, the behaviour file loaded,
// and the callbacks (init, step, on_dock, on_reload) held as registry references so a step
// costs one protected call and no name look-up.
#pragma once

#include <memory>
#include <string>

#include "script/lua_vm.h"
#include "world/module_handle.h"
#include "world/programs.h"

namespace rm3d {

/// What a behaviour's bindings reach: its module through a ModuleHandle (own records writable,
/// the rest of the world read-only; see world/module_handle.h), and the VM's registry refs.
struct BehaviourContext {
  ModuleHandle module;
  int stepRef = -2, initRef = -2, onDockRef = -2, onReloadRef = -2;  // LUA_NOREF
  int observeRef = -2, actRef = -2;  ///< observe() and act(a) for the Python API's arrays
  int actSize = -1;                  ///< the global act_size (a whole number >= 0), or -1
  int dockTableRef = -2;             ///< name -> Dock userdata
  /// Metatables of Joint and Dock, compared by address in each method call (cheaper than
  /// luaL_checkudata's registry look-up by name).
  const void* jointMeta = nullptr;
  const void* dockMeta = nullptr;
};

class Watchdog;

class Behaviour : public ModuleProgram {
 public:
  /// watchdog: the world's (null: none).
  Behaviour(const RunOptions& options, ModuleHandle module, Watchdog* watchdog);
  /// Loads and runs the behaviour file's top level. False and err on failure (the module faults).
  bool load(const std::string& path, std::string& err);
  bool init(std::string& err) override;
  bool step(double dt, std::string& err) override;
  /// on_dock(dock, event) if the behaviour defines it.
  bool onDock(int dock, DockEventKind event, std::string& err) override;
  /// Hot reload: runs new source for the behaviour in a scratch environment and, only if that
  /// succeeds, makes its definitions current (globals such as `state` survive) and calls
  /// on_reload(). On failure (syntax or run-time error) nothing changes; err has file:line.
  bool reload(const std::string& path, const std::string& source, std::string& err) override;
  void fetchState(int stage) const override;
  void noteHotLines() override;
  LuaVm& vm() { return m_vm; }
  /// module.__describe() (what the percept machinery declares), or "" / "(error)".
  std::string describePercepts() override;
  bool hasObserve() const override { return m_ctx.observeRef != -2; }
  bool observe(std::vector<double>& out, std::string& err) override;
  int actSize(int joints) const override;
  bool act(const double* a, int n, std::string& err) override;

 private:
  /// The lines step() read when last noted (script/lua_layout.h), fetched two modules ahead.
  /// (First of the fields: on the object's first line, with the table of virtual functions.)
  std::vector<const void*> m_hot;
  bool refreshCallbacks(std::string& err);
  void installLazyPrelude();
  /// Loads the percept machinery and checks `percepts`/`actions` if the behaviour declares any.
  bool checkDeclarations(const std::string& path, std::string& err);
  std::string locateDeclaration(const std::string& path, const std::string& err) const;
  LuaVm m_vm;
  BehaviourContext m_ctx;
  std::string m_file;  ///< the behaviour file as messages show it
};

}  // namespace rm3d
