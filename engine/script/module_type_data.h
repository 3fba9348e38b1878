// A module type's data as a plain Lua table, for scripts that model the robot (lua/kinematics.lua):
// world.module_type(name) on the world side, module.type_data([name]) in behaviours.
#pragma once

struct lua_State;

namespace rm3d {

struct ModuleTypeDef;

/// Pushes {name=, file=, root=, mass=, links={{name=, mass=, com=}}, joints={{name=, parent=, child=,
/// pivot=, axis=, lower=, upper=, continuous=, torque=, speed=, gain=}}, docks={{name=, link=, at=,
/// normal=, up=, quat=, gender=, size=, symmetry=, strength=, strength_torque=}}}: poses in the
/// module frame at zero joint angles (every link's frame); a dock's `quat` turns its link frame
/// into the dock frame (x the outward normal, z `up`).
void pushModuleTypeData(lua_State* L, const ModuleTypeDef& t);

}  // namespace rm3d
