// World side: the Module handle (rm3d.Module) the world script gets from world.spawn,
// world.module(s) and world.components: pose, joints, docks, sensors, pushes, fault injection.
#include <cmath>
#include <cstring>

#include "script/lua_options.h"
#include "script/lua_value.h"
#include "script/lua_vm.h"
#include "script/sensor_reading.h"
#include "script/world_bindings.h"
#include "world/world.h"

namespace rm3d {

namespace {

constexpr const char* kModuleMeta = "rm3d.Module";

const World& world(lua_State* L) {
  return scriptWorld(L);
}
WorldEditor& editor(lua_State* L) {
  return scriptEditor(L);
}

int checkJointName(lua_State* L, int arg, int module) {
  const char* name = luaL_checkstring(L, arg);
  const ModuleTypeDef& t = *world(L).module(module).type;
  const int j = t.findJoint(name);
  if (j < 0) return luaL_error(L, "no joint named '%s' on a %s", name, t.name.c_str());
  return j;
}

/// m:position() -> {x,y,z} of the module frame
int modulePosition(lua_State* L) {
  pushVec3(L, world(L).modulePose(checkModule(L, 1)).pos);
  return 1;
}

/// m:orientation() -> {w,x,y,z}
int moduleOrientation(lua_State* L) {
  pushQuat(L, world(L).modulePose(checkModule(L, 1)).rot);
  return 1;
}

/// m:velocity() -> {x,y,z} of the root link's centre of mass
int moduleVelocity(lua_State* L) {
  const int m = checkModule(L, 1);
  const Module& mod = world(L).module(m);
  pushVec3(L, world(L).physicsConst().partLinearVelocity(mod.parts[size_t(mod.type->rootLink)]));
  return 1;
}

/// m:link_position(name) -> {x,y,z} of a link frame
int moduleLinkPosition(lua_State* L) {
  const int m = checkModule(L, 1);
  const char* name = luaL_checkstring(L, 2);
  const int link = world(L).module(m).type->findLink(name);
  if (link < 0) return luaL_error(L, "no link named '%s'", name);
  pushVec3(L, world(L).linkPose(m, link).pos);
  return 1;
}

/// m:link_pose(name) -> {x,y,z}, {w,x,y,z}: a link frame in the world (the module frame at
/// zero joint angles, carried by the link)
int moduleLinkPose(lua_State* L) {
  const int m = checkModule(L, 1);
  const char* name = luaL_checkstring(L, 2);
  const int link = world(L).module(m).type->findLink(name);
  if (link < 0) return luaL_error(L, "no link named '%s'", name);
  const Pose p = world(L).linkPose(m, link);
  pushVec3(L, p.pos);
  pushQuat(L, p.rot);
  return 2;
}

/// m:joint_angle(name) -> radians
int moduleJointAngle(lua_State* L) {
  const int m = checkModule(L, 1);
  lua_pushnumber(L, world(L).jointAngle(m, checkJointName(L, 2, m)));
  return 1;
}

/// m:joint_torque(name) -> N m its motor applied over the last step, saturated (at its rating)
int moduleJointTorque(lua_State* L) {
  const int m = checkModule(L, 1);
  const int j = checkJointName(L, 2, m);
  lua_pushnumber(L, world(L).jointTorque(m, j));
  lua_pushboolean(L, world(L).jointSaturated(m, j));
  return 2;
}

/// m:joint_angles() -> {name = radians, ...}
int moduleJointAngles(lua_State* L) {
  const int m = checkModule(L, 1);
  const Module& mod = world(L).module(m);
  lua_createtable(L, 0, int(mod.type->joints.size()));
  for (size_t j = 0; j < mod.type->joints.size(); ++j) {
    lua_pushnumber(L, world(L).jointAngle(m, int(j)));
    lua_setfield(L, -2, mod.type->joints[j].name.c_str());
  }
  return 1;
}

/// m:dock_state(name) -> {enabled=, engaged=, peer_module= id or nil, peer_dock= name or nil}
int moduleDockState(lua_State* L) {
  const int m = checkModule(L, 1);
  const int d = checkDockName(L, 2, m);
  const DockState& s = world(L).module(m).docks[size_t(d)];
  lua_createtable(L, 0, 4);
  lua_pushboolean(L, s.enabled);
  lua_setfield(L, -2, "enabled");
  lua_pushboolean(L, s.engaged);
  lua_setfield(L, -2, "engaged");
  if (s.engaged) {
    const Module& peer = world(L).module(s.peerModule);
    lua_pushinteger(L, peer.id);
    lua_setfield(L, -2, "peer_module");
    lua_pushstring(L, peer.type->docks[size_t(s.peerDock)].name.c_str());
    lua_setfield(L, -2, "peer_dock");
  }
  return 1;
}

/// m:dock_gender(name) -> "none" | "male" | "female"
int moduleDockGender(lua_State* L) {
  const int m = checkModule(L, 1);
  const int d = checkDockName(L, 2, m);
  lua_pushstring(L, genderName(world(L).module(m).type->docks[size_t(d)].gender));
  return 1;
}

/// m:dock_position(name) -> {x,y,z} of the dock face centre
int moduleDockPosition(lua_State* L) {
  const int m = checkModule(L, 1);
  pushVec3(L, world(L).dockPose(m, checkDockName(L, 2, m)).pos);
  return 1;
}

/// m:dock_normal(name) -> {x,y,z} outward normal of the dock face
int moduleDockNormal(lua_State* L) {
  const int m = checkModule(L, 1);
  const Pose p = world(L).dockPose(m, checkDockName(L, 2, m));
  pushVec3(L, p.rot * Vec3::UnitX());
  return 1;
}

/// m:dock_load(name) -> {force=, torque=} through the connection at that dock in the last step
/// (N, N m about the dock face), or nil when nothing is engaged there
int moduleDockLoad(lua_State* L) {
  const int m = checkModule(L, 1);
  const int d = checkDockName(L, 2, m);
  for (const Connection& c : world(L).connections())
    if ((c.moduleA == m && c.dockA == d) || (c.moduleB == m && c.dockB == d)) {
      const Wrench w = world(L).connectionLoad(c);
      lua_createtable(L, 0, 2);
      lua_pushnumber(L, w.force.norm());
      lua_setfield(L, -2, "force");
      lua_pushnumber(L, w.torque.norm());
      lua_setfield(L, -2, "torque");
      return 1;
    }
  lua_pushnil(L);
  return 1;
}

/// m:set_dock(name, enabled): enable or disable a dock from the world (a fault injection, a
/// supervisor); a disabled dock releases its connection in the next step
int moduleSetDock(lua_State* L) {
  const int m = checkModule(L, 1);
  const int d = checkDockName(L, 2, m);
  luaL_checktype(L, 3, LUA_TBOOLEAN);
  const Module& mod = world(L).module(m);
  if (!mod.fault.empty())
    return luaL_error(L, "set_dock: %s is faulted; its docks cannot change", mod.name.c_str());
  editor(L).setDockEnabled(m, d, lua_toboolean(L, 3));
  return 0;
}

/// Largest force a push may ask for, N. Larger finite forces are refused here; up to it, a body
/// that is flung too fast is stopped by the divergence check (world/divergence.h).
constexpr double kMaxPush = 1e9;

/// m:push({x,y,z}) : a force (N, at most 1e9 in magnitude) on the module's root link during the next step
int modulePush(lua_State* L) {
  const int m = checkModule(L, 1);
  double v[3];
  luaL_checktype(L, 2, LUA_TTABLE);
  for (int i = 0; i < 3; ++i) {
    lua_rawgeti(L, 2, i + 1);
    int isnum = 0;
    v[i] = lua_tonumberx(L, -1, &isnum);
    if (!isnum) return luaL_argerror(L, 2, "expected a force {x, y, z} in newtons");
    if (!std::isfinite(v[i]))
      return luaL_error(L, "m:push: the force must be finite, got component %d = %s", i + 1, numText(v[i]).s);
    lua_pop(L, 1);
  }
  const double f = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
  if (!(f <= kMaxPush))
    return luaL_error(L, "m:push: the force must be at most %s N in magnitude, got {%s, %s, %s} (%s N)",
                      numText(kMaxPush).s, numText(v[0]).s, numText(v[1]).s, numText(v[2]).s, numText(f).s);
  editor(L).pushModule(m, Vec3(v[0], v[1], v[2]));
  return 0;
}

int checkSensorName(lua_State* L, int arg, int module) {
  const char* name = luaL_checkstring(L, arg);
  const int code = world(L).sensorCode(module, name);
  if (code >= 0) return code;
  lua_pushfstring(L, "no sensor named '%s' on a %s (it has: %s)", name,
                  world(L).module(module).type->name.c_str(), world(L).sensorNames(module).c_str());
  luaL_where(L, 1);
  lua_insert(L, -2);
  lua_concat(L, 2);
  return lua_error(L);
}

/// m:sensor(name [, "velocity"]) -> the module's raw sensor reading now (as module.sensor)
int moduleSensorRead(lua_State* L) {
  const int m = checkModule(L, 1);
  const int code = checkSensorName(L, 2, m);
  bool velocity = false;
  if (!lua_isnoneornil(L, 3)) {
    static const char* const fields[] = {"velocity", nullptr};
    luaL_checkoption(L, 3, nullptr, fields);
    velocity = true;
  }
  pushSensorReading(L, editor(L).readSensor(m, code, velocity));
  return 1;
}

/// m:inject_fault{joint = name} | {dock = name} | {sensor = name}: from now on the joint stalls
/// where it is, the dock no longer latches, or the sensor reads nil
int moduleInjectFault(lua_State* L) {
  const int m = checkModule(L, 1);
  checkOptionKeys(L, 2, "inject_fault", {"joint", "dock", "sensor"});
  int given = 0;
  if (lua_getfield(L, 2, "joint") != LUA_TNIL) {
    const char* name = luaL_checkstring(L, -1);
    const int j = world(L).module(m).type->findJoint(name);
    if (j < 0) return luaL_error(L, "inject_fault: no joint named '%s'", name);
    editor(L).stallJoint(m, j);
    ++given;
  }
  if (lua_getfield(L, 2, "dock") != LUA_TNIL) {
    editor(L).blockDock(m, checkDockName(L, -1, m));
    ++given;
  }
  if (lua_getfield(L, 2, "sensor") != LUA_TNIL) {
    editor(L).killSensor(m, checkSensorName(L, lua_gettop(L), m));
    ++given;
  }
  if (given == 0) return luaL_error(L, "inject_fault: name a joint, dock or sensor");
  return 0;
}

/// m:published([key]) -> a copy of the value the module's behaviour last published under key
/// (module.publish), or nil; without a key, a table of every key and value
int modulePublished(lua_State* L) {
  const Module& mod = world(L).module(checkModule(L, 1));
  if (lua_isnoneornil(L, 2)) {
    lua_createtable(L, 0, int(mod.published.size()));
    for (const auto& [key, value] : mod.published) {
      pushLuaValue(L, value);
      lua_setfield(L, -2, key.c_str());
    }
    return 1;
  }
  const char* key = luaL_checkstring(L, 2);
  for (const auto& [k, value] : mod.published) {
    if (k == key) {
      pushLuaValue(L, value);
      return 1;
    }
  }
  lua_pushnil(L);
  return 1;
}

/// m:error() -> nil, or the module's fault text
int moduleError(lua_State* L) {
  const Module& mod = world(L).module(checkModule(L, 1));
  if (mod.fault.empty())
    lua_pushnil(L);
  else
    lua_pushstring(L, mod.fault.c_str());
  return 1;
}

int moduleIndex(lua_State* L) {
  const int m = checkModule(L, 1);
  const char* key = luaL_checkstring(L, 2);
  const Module& mod = world(L).module(m);
  if (std::strcmp(key, "id") == 0)
    lua_pushinteger(L, mod.id);
  else if (std::strcmp(key, "name") == 0)
    lua_pushstring(L, mod.name.c_str());
  else if (std::strcmp(key, "type") == 0)
    lua_pushstring(L, mod.type->name.c_str());
  else {
    lua_getmetatable(L, 1);
    lua_getfield(L, -1, "methods");
    lua_getfield(L, -1, key);
  }
  return 1;
}

int moduleToString(lua_State* L) {
  const Module& mod = world(L).module(checkModule(L, 1));
  lua_pushfstring(L, "Module(%d %s)", mod.id, mod.name.c_str());
  return 1;
}

int moduleEq(lua_State* L) {
  lua_pushboolean(L, checkModule(L, 1) == checkModule(L, 2));
  return 1;
}

}  // namespace

void openModuleHandle(lua_State* L) {
  static const luaL_Reg moduleMethods[] = {
      {"position", modulePosition},        {"orientation", moduleOrientation},
      {"velocity", moduleVelocity},        {"link_position", moduleLinkPosition},
      {"link_pose", moduleLinkPose},       {"joint_angle", moduleJointAngle},
      {"joint_angles", moduleJointAngles}, {"joint_torque", moduleJointTorque},
      {"dock_state", moduleDockState},     {"dock_position", moduleDockPosition},
      {"dock_normal", moduleDockNormal},   {"error", moduleError},
      {"published", modulePublished},      {"dock_load", moduleDockLoad},
      {"set_dock", moduleSetDock},         {"push", modulePush},
      {"dock_gender", moduleDockGender},   {"sensor", moduleSensorRead},
      {"inject_fault", moduleInjectFault}, {nullptr, nullptr}};
  luaL_newmetatable(L, kModuleMeta);
  sealMetatable(L);
  luaL_newlib(L, moduleMethods);
  lua_setfield(L, -2, "methods");
  lua_pushcfunction(L, moduleIndex);
  lua_setfield(L, -2, "__index");
  lua_pushcfunction(L, moduleToString);
  lua_setfield(L, -2, "__tostring");
  lua_pushcfunction(L, moduleEq);
  lua_setfield(L, -2, "__eq");
  lua_pop(L, 1);
}

void pushModule(lua_State* L, int index) {
  *static_cast<int*>(lua_newuserdatauv(L, sizeof(int), 0)) = index;
  luaL_setmetatable(L, kModuleMeta);
}

int checkModule(lua_State* L, int arg) {
  return *static_cast<int*>(luaL_checkudata(L, arg, kModuleMeta));
}

int checkDockName(lua_State* L, int arg, int module) {
  const char* name = luaL_checkstring(L, arg);
  const ModuleTypeDef& t = *world(L).module(module).type;
  const int d = t.findDock(name);
  if (d >= 0) return d;
  luaL_where(L, 1);
  lua_pushfstring(L, "no dock named '%s' on a %s (it has:", name, t.name.c_str());
  for (size_t i = 0; i < t.docks.size(); ++i)
    lua_pushfstring(L, "%s%s", i ? ", " : " ", t.docks[i].name.c_str());
  lua_pushliteral(L, ")");
  lua_concat(L, int(t.docks.size()) + 3);
  return lua_error(L);
}

}  // namespace rm3d
