// Behaviour side: the Joint type (module.joint(name) -> userdata {index}): angle, velocity,
// set_target, set_velocity, free, target, name, limits.
#include <cmath>
#include <lua.hpp>

#include "script/behaviour.h"
#include "script/behaviour_bindings.h"
#include "script/lua_vm.h"
#include "world/world.h"

namespace rm3d {

namespace {

constexpr const char* kJointMeta = "rm3d.Joint";

struct JointUd {
  int index;
};

int checkJoint(lua_State* L) {
  return checkIndexUserdata(L, behaviourContext(L).jointMeta, kJointMeta);
}

/// joint:angle() -> radians (child relative to parent, about the axis)
int jointAngle(lua_State* L) {
  const int j = checkJoint(L);
  const BehaviourContext& c = behaviourContext(L);
  lua_pushnumber(L, c.module.world().jointAngle(c.module.index(), j));
  return 1;
}

/// joint:velocity() -> rad/s
int jointVelocity(lua_State* L) {
  const int j = checkJoint(L);
  const BehaviourContext& c = behaviourContext(L);
  lua_pushnumber(L, c.module.world().jointVelocity(c.module.index(), j));
  return 1;
}

/// joint:torque() -> N m the motor applied over the last step, saturated (true at its rating)
int jointTorque(lua_State* L) {
  const int j = checkJoint(L);
  const BehaviourContext& c = behaviourContext(L);
  lua_pushnumber(L, c.module.world().jointTorque(c.module.index(), j));
  lua_pushboolean(L, c.module.world().jointSaturated(c.module.index(), j));
  return 2;
}

/// joint:saturated() -> true when the motor gave its rated torque over the last step
int jointSaturated(lua_State* L) {
  const int j = checkJoint(L);
  const BehaviourContext& c = behaviourContext(L);
  lua_pushboolean(L, c.module.world().jointSaturated(c.module.index(), j));
  return 1;
}

/// joint:set_target(rad): position servo, within the joint's limits, torque and speed
int jointSetTarget(lua_State* L) {
  const int j = checkJoint(L);
  const double v = checkFinite(L, 2);
  const BehaviourContext& c = behaviourContext(L);
  c.module.self().commands[size_t(j)] = {JointMode::Servo, v};
  return 0;
}

/// joint:set_velocity(rad_s): velocity drive, within torque and speed
int jointSetVelocity(lua_State* L) {
  const int j = checkJoint(L);
  const double v = checkFinite(L, 2);
  const BehaviourContext& c = behaviourContext(L);
  c.module.self().commands[size_t(j)] = {JointMode::Velocity, v};
  return 0;
}

/// joint:free(): motor off, the joint swings freely (within its limits)
int jointFree(lua_State* L) {
  const int j = checkJoint(L);
  const BehaviourContext& c = behaviourContext(L);
  c.module.self().commands[size_t(j)] = {JointMode::Off, 0};
  return 0;
}

/// joint:target() -> the last servo target, or nil when not in servo mode
int jointTarget(lua_State* L) {
  const int j = checkJoint(L);
  const BehaviourContext& c = behaviourContext(L);
  const JointCommand& cmd = c.module.self().commands[size_t(j)];
  if (cmd.mode == JointMode::Servo)
    lua_pushnumber(L, cmd.value);
  else
    lua_pushnil(L);
  return 1;
}

/// joint:name() -> string
int jointName(lua_State* L) {
  const int j = checkJoint(L);
  const BehaviourContext& c = behaviourContext(L);
  lua_pushstring(L, c.module.self().type->joints[size_t(j)].name.c_str());
  return 1;
}

/// joint:limits() -> lower, upper (radians; -inf, inf when continuous)
int jointLimits(lua_State* L) {
  const int j = checkJoint(L);
  const BehaviourContext& c = behaviourContext(L);
  const JointDef& d = c.module.self().type->joints[size_t(j)];
  lua_pushnumber(L, d.limited ? d.lower : -HUGE_VAL);
  lua_pushnumber(L, d.limited ? d.upper : HUGE_VAL);
  return 2;
}

int jointToString(lua_State* L) {
  const int j = checkJoint(L);
  const BehaviourContext& c = behaviourContext(L);
  lua_pushfstring(L, "Joint(%s)", c.module.self().type->joints[size_t(j)].name.c_str());
  return 1;
}

}  // namespace

void openJointType(lua_State* L) {
  static const luaL_Reg methods[] = {{"angle", jointAngle},
                                     {"velocity", jointVelocity},
                                     {"torque", jointTorque},
                                     {"saturated", jointSaturated},
                                     {"set_target", jointSetTarget},
                                     {"set_velocity", jointSetVelocity},
                                     {"free", jointFree},
                                     {"target", jointTarget},
                                     {"name", jointName},
                                     {"limits", jointLimits},
                                     {nullptr, nullptr}};
  luaL_newmetatable(L, kJointMeta);
  sealMetatable(L);
  behaviourContext(L).jointMeta = lua_topointer(L, -1);
  luaL_newlib(L, methods);
  lua_setfield(L, -2, "__index");
  lua_pushcfunction(L, jointToString);
  lua_setfield(L, -2, "__tostring");
  lua_pop(L, 1);
}

/// Pushes a new Joint userdata (used once per joint when the VM is set up, then cached).
void pushJoint(lua_State* L, int index) {
  auto* ud = static_cast<JointUd*>(lua_newuserdatauv(L, sizeof(JointUd), 0));
  ud->index = index;
  luaL_setmetatable(L, kJointMeta);
}

}  // namespace rm3d
