// Both sides: a sensor reading as the Lua value behaviours (module.sensor) and the world
// script (Module:sensor) see.
#include "script/sensor_reading.h"

#include <lua.hpp>

#include "script/lua_options.h"
#include "world/world.h"

namespace rm3d {

void pushSensorReading(lua_State* L, const SensorReading& r) {
  switch (r.kind) {
    case SensorReading::Kind::Nil:
      lua_pushnil(L);
      break;
    case SensorReading::Kind::Number:
      lua_pushnumber(L, r.v[0]);
      break;
    case SensorReading::Kind::Boolean:
      lua_pushboolean(L, r.flag);
      break;
    case SensorReading::Kind::Vector:
      pushVec3(L, Vec3(r.v[0], r.v[1], r.v[2]));
      break;
    case SensorReading::Kind::Quaternion:
      pushQuat(L, Quat(r.v[0], r.v[1], r.v[2], r.v[3]));
      break;
    case SensorReading::Kind::Dock:
      lua_createtable(L, 0, 4);
      lua_pushboolean(L, r.flag);
      lua_setfield(L, -2, "enabled");
      lua_pushboolean(L, r.engaged);
      lua_setfield(L, -2, "engaged");
      if (r.proximity >= 0) {
        lua_pushnumber(L, r.proximity);
        lua_setfield(L, -2, "proximity");
      }
      if (r.hasBearing) {
        pushVec3(L, Vec3(r.v[0], r.v[1], r.v[2]));
        lua_setfield(L, -2, "bearing");
      }
      break;
  }
}

}  // namespace rm3d
