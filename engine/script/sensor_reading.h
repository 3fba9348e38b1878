// Both sides: how a sensor reading appears in Lua (behaviour_module.cpp, world_module.cpp).
#pragma once

struct lua_State;

namespace rm3d {

struct SensorReading;

/// Pushes a sensor reading as the Lua value behaviours see: nil, a number, a boolean, {x,y,z},
/// {w,x,y,z} or a dock's {enabled=, engaged=, proximity=, bearing=}.
void pushSensorReading(lua_State* L, const SensorReading& r);

}  // namespace rm3d
