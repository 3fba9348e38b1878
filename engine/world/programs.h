// What the World needs of the scripts that drive it, as interfaces: the script layer (script/)
// implements them with Lua VMs, so world/, docking/ and messaging/ neither include nor know Lua.
//
//   ScriptHost     made when a world is loaded (World::loadFile, defined by the script layer);
//                  reads module types (they are Lua data), makes a module's program when a
//                  module with a behaviour is spawned, and owns what the VMs share (the
//                  watchdog). It outlives every program.
//   WorldProgram   the world script: its hooks run after each step.
//   ModuleProgram  a module's behaviour: init, step, on_dock, hot reload.
//
// Every call returns false with a message ("file:line: ...") when the script failed; the World
// then faults that module (or records a world-script error) and runs on.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "docking/dock_event.h"
#include "modules/module_type.h"

namespace rm3d {

class ModuleHandle;

/// The longest observation row observe() may return, and the largest act_size.
constexpr int kMaxObsSize = 4096;
constexpr int kMaxActSize = 4096;

class ModuleProgram {
 public:
  virtual ~ModuleProgram() = default;
  virtual bool init(std::string& err) = 0;
  virtual bool step(double dt, std::string& err) = 0;
  /// on_dock(dock, event); event is "engaged", "disengaged" or "broken".
  virtual bool onDock(int dock, DockEventKind event, std::string& err) = 0;
  /// Hot reload: new source for the program's file; on failure the old code keeps running.
  virtual bool reload(const std::string& path, const std::string& source, std::string& err) = 0;
  /// Declared percepts and their last values, one "name = value" per line (viewer).
  virtual std::string describePercepts() = 0;

  // --- agents (the Python API's arrays: docs/python.md) ---
  /// True when the behaviour defines observe().
  virtual bool hasObserve() const { return false; }
  /// observe(): the module's observation row, appended to `out`. False and err on an error.
  virtual bool observe(std::vector<double>& out, std::string& err) { return true; }
  /// The length of the action row act(a) takes: the global act_size, else `joints`; -1 when the
  /// behaviour defines no act().
  virtual int actSize(int joints) const { return -1; }
  /// act(a) with the module's action row. False and err on an error.
  virtual bool act(const double* a, int n, std::string& err) { return true; }
  /// Starts fetching the state that step() will read into the caches, with thousands of modules
  /// cold since the module's last step: the world calls it three modules ahead (stage 2), two
  /// ahead (stage 1) and one ahead (stage 0), each stage reading only what the one before fetched
  /// (stage 2 only the program's first line, which the world fetched four ahead). No effect on
  /// any result.
  virtual void fetchState(int stage) const {}
  /// Notes what fetchState() fetches beyond the program's own fields (the world calls it between
  /// steps, on one thread, now and then: what a program reads moves as its state grows). No
  /// effect on any result.
  virtual void noteHotLines() {}
};

class WorldProgram {
 public:
  virtual ~WorldProgram() = default;
  /// Calls the hooks due at time t (after each step).
  virtual bool afterStep(double t, std::string& err) = 0;
  /// world.reward(fn) / world.done(fn) were given.
  virtual bool hasReward() const { return false; }
  virtual bool hasDone() const { return false; }
  /// Calls world.reward's fn and writes one number per module (`out` has room for `modules`).
  virtual bool reward(int modules, double* out, std::string& err) { return true; }
  /// Calls world.done's fn and writes one flag per module.
  virtual bool done(int modules, uint8_t* out, std::string& err) { return true; }
};

class ScriptHost {
 public:
  virtual ~ScriptHost() = default;
  /// Reads a module-type file (assets/modules/*.lua). Throws InputError naming file:line.
  virtual ModuleTypeDef loadModuleType(const std::string& path) = 0;
  /// Loads a behaviour file into a new program for the module. On failure err is set and the
  /// program is still returned (the module faults; a hot reload that loads cleanly revives it).
  virtual std::unique_ptr<ModuleProgram> loadBehaviour(const ModuleHandle& module, const std::string& path,
                                                       std::string& err) = 0;
};

}  // namespace rm3d
