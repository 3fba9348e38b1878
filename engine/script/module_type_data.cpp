// Module-type data for scripts: the ModuleTypeDef as nested Lua tables (names, not indices).
#include "script/module_type_data.h"

#include <lua.hpp>

#include "modules/module_type.h"
#include "physics/shape_def.h"
#include "script/lua_options.h"

namespace rm3d {

namespace {

void setNumber(lua_State* L, const char* key, double v) {
  lua_pushnumber(L, v);
  lua_setfield(L, -2, key);
}

void setString(lua_State* L, const char* key, const std::string& v) {
  lua_pushlstring(L, v.data(), v.size());
  lua_setfield(L, -2, key);
}

void setVec3(lua_State* L, const char* key, const Vec3& v) {
  pushVec3(L, v);
  lua_setfield(L, -2, key);
}

}  // namespace

void pushModuleTypeData(lua_State* L, const ModuleTypeDef& t) {
  lua_createtable(L, 0, 7);
  setString(L, "name", t.name);
  setString(L, "file", t.file);
  setString(L, "root", t.links[size_t(t.rootLink)].name);
  setNumber(L, "mass", t.mass());
  lua_createtable(L, int(t.links.size()), 0);
  for (size_t i = 0; i < t.links.size(); ++i) {
    const LinkDef& l = t.links[i];
    lua_createtable(L, 0, 3);
    setString(L, "name", l.name);
    setNumber(L, "mass", l.mass);
    setVec3(L, "com", compoundMassProps(l.shapes, l.mass).com);
    lua_rawseti(L, -2, lua_Integer(i + 1));
  }
  lua_setfield(L, -2, "links");
  lua_createtable(L, int(t.joints.size()), 0);
  for (size_t i = 0; i < t.joints.size(); ++i) {
    const JointDef& j = t.joints[i];
    lua_createtable(L, 0, 11);
    setString(L, "name", j.name);
    setString(L, "parent", t.links[size_t(j.parent)].name);
    setString(L, "child", t.links[size_t(j.child)].name);
    setVec3(L, "pivot", j.pivot);
    setVec3(L, "axis", j.axis);
    setNumber(L, "lower", j.lower);
    setNumber(L, "upper", j.upper);
    lua_pushboolean(L, !j.limited);
    lua_setfield(L, -2, "continuous");
    setNumber(L, "torque", j.maxTorque);
    setNumber(L, "speed", j.maxSpeed);
    setNumber(L, "gain", j.servoGain);
    setNumber(L, "stiffness", j.servoStiffness);
    lua_rawseti(L, -2, lua_Integer(i + 1));
  }
  lua_setfield(L, -2, "joints");
  lua_createtable(L, int(t.docks.size()), 0);
  for (size_t i = 0; i < t.docks.size(); ++i) {
    const DockDef& d = t.docks[i];
    lua_createtable(L, 0, 11);
    setString(L, "name", d.name);
    setString(L, "link", t.links[size_t(d.link)].name);
    setVec3(L, "at", d.pos);
    setVec3(L, "normal", d.normal);
    setVec3(L, "up", d.up);
    pushQuat(L, d.frame.rot);
    lua_setfield(L, -2, "quat");
    lua_pushstring(L, genderName(d.gender));
    lua_setfield(L, -2, "gender");
    setNumber(L, "size", d.size);
    lua_pushinteger(L, d.symmetry);
    lua_setfield(L, -2, "symmetry");
    setNumber(L, "strength", d.strength);
    setNumber(L, "strength_torque", d.strengthTorque);
    lua_rawseti(L, -2, lua_Integer(i + 1));
  }
  lua_setfield(L, -2, "docks");
}

}  // namespace rm3d
