// Behaviour side: the `module` table (identity, joints, docks, messages, percepts) of a
// behaviour VM, the helpers the behaviour bindings share, and openModuleApi, which sets up a
// behaviour VM's globals (`module`, `sim` and `log` from behaviour_sim.cpp, `params`, `state`).
#include <cmath>
#include <cstdio>
#include <lua.hpp>
#include <nlohmann/json.hpp>
#include <string>

#include "script/behaviour.h"
#include "script/behaviour_bindings.h"
#include "script/lua_options.h"
#include "script/lua_value.h"
#include "script/module_type_data.h"
#include "script/sensor_reading.h"
#include "script/trace_binding.h"
#include "world/world.h"

namespace rm3d {

namespace {

Module& self(lua_State* L) {
  return behaviourContext(L).module.self();
}

/// Looks `name` up in the cache table stored as upvalue 1; errors listing the valid names.
int lookupNamed(lua_State* L, const char* what) {
  const char* name = luaL_checkstring(L, 1);
  lua_pushvalue(L, 1);
  if (lua_rawget(L, lua_upvalueindex(1)) != LUA_TNIL) return 1;
  luaL_where(L, 1);
  lua_pushfstring(L, "module.%s: no %s named '%s' on a %s (it has:", what, what, name,
                  self(L).type->name.c_str());
  luaL_Buffer b;
  luaL_buffinit(L, &b);
  int n = 0;
  // names in declaration order come from the type, not from the hash table
  const ModuleTypeDef& t = *self(L).type;
  const bool joints = what[0] == 'j';
  const size_t count = joints ? t.joints.size() : t.docks.size();
  for (size_t i = 0; i < count; ++i) {
    luaL_addstring(&b, n++ ? ", " : " ");
    luaL_addstring(&b, joints ? t.joints[i].name.c_str() : t.docks[i].name.c_str());
  }
  luaL_addstring(&b, ")");
  luaL_pushresult(&b);
  lua_concat(L, 3);
  return lua_error(L);
}

/// module.joint(name) -> Joint
int moduleJoint(lua_State* L) {
  return lookupNamed(L, "joint");
}
/// module.dock(name) -> Dock
int moduleDock(lua_State* L) {
  return lookupNamed(L, "dock");
}

/// module.joints() -> array of joint names
int moduleJoints(lua_State* L) {
  const ModuleTypeDef& t = *self(L).type;
  lua_createtable(L, int(t.joints.size()), 0);
  for (size_t i = 0; i < t.joints.size(); ++i) {
    lua_pushstring(L, t.joints[i].name.c_str());
    lua_rawseti(L, -2, lua_Integer(i + 1));
  }
  return 1;
}

/// module.type_data([name]) -> the data of this module's type, or of another type the world has
/// spawned (script/module_type_data.h)
int moduleTypeData(lua_State* L) {
  const ModuleTypeDef* type = self(L).type;
  if (!lua_isnoneornil(L, 1)) {
    size_t len = 0;
    const char* name = luaL_checklstring(L, 1, &len);
    {
      const std::string key(name, len);
      type = behaviourContext(L).module.world().loadedModuleType(key);
    }
    if (!type)
      return luaL_error(
          L, "module.type_data: no module type '%s' in this world (expected the type of a spawned module)",
          name);
  }
  pushModuleTypeData(L, *type);
  return 1;
}

/// module.docks() -> array of dock names
int moduleDocks(lua_State* L) {
  const ModuleTypeDef& t = *self(L).type;
  lua_createtable(L, int(t.docks.size()), 0);
  for (size_t i = 0; i < t.docks.size(); ++i) {
    lua_pushstring(L, t.docks[i].name.c_str());
    lua_rawseti(L, -2, lua_Integer(i + 1));
  }
  return 1;
}

/// module.receive([dock]) -> {dock=, data=, time=} or nil: the oldest pending message, consumed
int moduleReceive(lua_State* L) {
  const BehaviourContext& c = behaviourContext(L);
  int dock = -1;
  if (!lua_isnoneornil(L, 1)) {
    const char* name = nullptr;
    if (lua_type(L, 1) == LUA_TSTRING) {
      name = lua_tostring(L, 1);
      dock = self(L).type->findDock(name);
    } else {
      lua_getmetatable(L, 1);
      luaL_getmetatable(L, "rm3d.Dock");
      const bool isDock = lua_rawequal(L, -1, -2);
      lua_pop(L, 2);
      if (isDock) dock = *static_cast<int*>(lua_touserdata(L, 1));
    }
    if (dock < 0) return luaL_argerror(L, 1, "expected a dock name or Dock of this module");
  }
  Mailbox& box = c.module.mailbox();
  if (box.inbox.empty()) return 0;
  Message msg;
  if (!box.take(dock, msg)) return 0;
  if (c.module.world().options().keepHistory) {
    Module& me = self(L);
    char head[64];
    std::snprintf(head, sizeof head, "%.2f %s: ", msg.time, me.type->docks[size_t(msg.dock)].name.c_str());
    me.recentMessages.push_back(
        head + valueToJson(msg.data).dump(-1, ' ', false, nlohmann::json::error_handler_t::replace));
    if (me.recentMessages.size() > 20) me.recentMessages.pop_front();
  }
  lua_createtable(L, 0, 3);
  lua_pushstring(L, self(L).type->docks[size_t(msg.dock)].name.c_str());
  lua_setfield(L, -2, "dock");
  pushLuaValue(L, msg.data);
  lua_setfield(L, -2, "data");
  lua_pushnumber(L, msg.time);
  lua_setfield(L, -2, "time");
  return 1;
}

/// module.sensor(name [, "velocity"]) -> the raw reading this step: a number (joint angle or
/// speed, range distance), {x,y,z} (accelerometer, gyro, position), {w,x,y,z} (orientation), a
/// boolean (contact), {enabled=, engaged=, proximity=, bearing=} (dock), or nil (nothing in range,
/// dead)
int moduleSensor(lua_State* L) {
  luaL_checkstring(L, 1);
  bool velocity = false;
  if (!lua_isnoneornil(L, 2)) {  // before anything is pushed above the arguments
    static const char* const fields[] = {"velocity", nullptr};
    luaL_checkoption(L, 2, nullptr, fields);
    velocity = true;
  }
  lua_settop(L, 1);
  lua_pushvalue(L, 1);
  if (lua_rawget(L, lua_upvalueindex(1)) != LUA_TNUMBER) {
    const BehaviourContext& c = behaviourContext(L);
    lua_pushfstring(L, "module.sensor: no sensor named '%s' on a %s", lua_tostring(L, 1),
                    self(L).type->name.c_str());
    luaL_where(L, 1);
    lua_insert(L, -2);
    lua_pushfstring(L, " (it has: %s)", c.module.world().sensorNames(c.module.index()).c_str());
    lua_concat(L, 3);
    return lua_error(L);
  }
  const int code = int(lua_tointeger(L, -1));
  const BehaviourContext& c = behaviourContext(L);
  pushSensorReading(L, c.module.readSensor(code, velocity));
  return 1;
}

/// module.has_sensor(name) -> true, or false and the list of the type's sensors
int moduleHasSensor(lua_State* L) {
  luaL_checkstring(L, 1);
  lua_pushvalue(L, 1);
  if (lua_rawget(L, lua_upvalueindex(1)) == LUA_TNUMBER) {
    lua_pushboolean(L, 1);
    return 1;
  }
  const BehaviourContext& c = behaviourContext(L);
  lua_pushboolean(L, 0);
  lua_pushstring(L, c.module.world().sensorNames(c.module.index()).c_str());
  return 2;
}

/// module.trace(name, value): records a series for `rm3d run --trace` (column trace.<name> of the
/// module's rows) and the viewer; name: letters, digits, _ . -; value: a finite number
int moduleTrace(lua_State* L) {
  return recordSeries(L, self(L).traces, "module.trace", "one behaviour");
}

/// module.publish(key, value): makes a plain value (as a message payload, at most 64 KiB) readable
/// by the world script as m:published(key), until published again; nil removes the key
int modulePublish(lua_State* L) {
  const char* key = checkSeriesName(L, 1, "module.publish");
  auto& published = self(L).published;
  auto it = published.begin();
  while (it != published.end() && it->first != key) ++it;
  if (lua_isnoneornil(L, 2)) {
    if (it != published.end()) published.erase(it);
    return 0;
  }
  // Lua errors are longjmps: the value and its message are gone before one is raised.
  char message[512] = "";
  {
    Value v;
    std::string err;
    if (!readLuaValue(L, 2, v, kMaxPublishedBytes, err))
      std::snprintf(message, sizeof message, "module.publish: %s", err.c_str());
    else if (it != published.end())
      it->second = std::move(v);
    else if (published.size() >= kMaxPublishedKeys)
      std::snprintf(message, sizeof message,
                    "module.publish: too many keys in one module (at most %d); '%s' is one more",
                    int(kMaxPublishedKeys), key);
    else
      published.emplace_back(key, std::move(v));
  }
  if (message[0]) return luaL_error(L, "%s", message);
  return 0;
}

void setFunctions(lua_State* L, const luaL_Reg* fns) {
  luaL_setfuncs(L, fns, 0);
}

}  // namespace

BehaviourContext& behaviourContext(lua_State* L) {
  return *static_cast<BehaviourContext*>(LuaVm::from(L)->user());
}

int checkIndexUserdata(lua_State* L, const void* meta, const char* typeName) {
  void* p = lua_touserdata(L, 1);
  if (p && lua_getmetatable(L, 1)) {
    const bool same = lua_topointer(L, -1) == meta;
    lua_pop(L, 1);
    if (same) return *static_cast<int*>(p);  // JointUd and DockUd hold just the index
  }
  return *static_cast<int*>(luaL_checkudata(L, 1, typeName));  // the standard error
}

double checkFinite(lua_State* L, int arg) {
  const double v = luaL_checknumber(L, arg);
  if (!std::isfinite(v)) luaL_argerror(L, arg, "expected a finite number");
  return v;
}

void openModuleApi(lua_State* L, BehaviourContext& ctx) {
  openJointType(L);
  openDockType(L);
  const Module& m = ctx.module.self();

  lua_newtable(L);  // module
  lua_pushinteger(L, m.id);
  lua_setfield(L, -2, "id");
  lua_pushstring(L, m.name.c_str());
  lua_setfield(L, -2, "name");
  lua_pushstring(L, m.type->name.c_str());
  lua_setfield(L, -2, "type");
  // Joint and Dock objects are made once and cached by name.
  lua_createtable(L, 0, int(m.type->joints.size()));
  for (size_t i = 0; i < m.type->joints.size(); ++i) {
    pushJoint(L, int(i));
    lua_setfield(L, -2, m.type->joints[i].name.c_str());
  }
  lua_pushcclosure(L, moduleJoint, 1);
  lua_setfield(L, -2, "joint");
  lua_createtable(L, 0, int(m.type->docks.size()));
  for (size_t i = 0; i < m.type->docks.size(); ++i) {
    pushDock(L, int(i));
    lua_setfield(L, -2, m.type->docks[i].name.c_str());
  }
  lua_pushvalue(L, -1);
  ctx.dockTableRef = luaL_ref(L, LUA_REGISTRYINDEX);
  lua_pushcclosure(L, moduleDock, 1);
  lua_setfield(L, -2, "dock");
  static const luaL_Reg moduleFns[] = {{"joints", moduleJoints},      {"docks", moduleDocks},
                                       {"receive", moduleReceive},    {"publish", modulePublish},
                                       {"type_data", moduleTypeData}, {nullptr, nullptr}};
  setFunctions(L, moduleFns);
  pushSeriesClosure(L, moduleTrace);
  lua_setfield(L, -2, "trace");
  // Sensor names -> codes, looked up in a Lua table (interned strings), not parsed per read.
  lua_newtable(L);
  {
    const ModuleTypeDef& t = *m.type;
    int code = 0;
    for (const JointDef& j : t.joints) {
      lua_pushinteger(L, code++);
      lua_setfield(L, -2, ("joint:" + j.name).c_str());
    }
    for (const DockDef& d : t.docks) {
      lua_pushinteger(L, code++);
      lua_setfield(L, -2, ("dock:" + d.name).c_str());
    }
    for (const SensorDef& s : t.sensors) {
      lua_pushinteger(L, code++);
      lua_setfield(L, -2, s.name.c_str());
    }
  }
  lua_pushvalue(L, -1);
  lua_pushcclosure(L, moduleSensor, 1);
  lua_setfield(L, -3, "sensor");
  lua_pushcclosure(L, moduleHasSensor, 1);
  lua_setfield(L, -2, "has_sensor");
  lua_setglobal(L, "module");

  openSimApi(L);

  pushLuaValue(L, m.params);
  if (!lua_istable(L, -1)) {
    lua_pop(L, 1);
    lua_newtable(L);
  }
  lua_setglobal(L, "params");
  lua_newtable(L);
  lua_setglobal(L, "state");
}

}  // namespace rm3d
