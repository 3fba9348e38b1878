// World side: the world script's `world` table, `expect`, `args` and `log`/`print`. Calls into
// World may throw InputError; callWorld converts it into a Lua error with the caller's file:line.
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <lua.hpp>
#include <optional>
#include <string>
#include <string_view>

#include "core/error.h"
#include "core/param_value.h"
#include "docking/dock_frame.h"
#include "io/graph_export.h"
#include "script/lua_options.h"
#include "script/lua_value.h"
#include "script/module_type_data.h"
#include "script/trace_binding.h"
#include "script/world_bindings.h"
#include "script/world_script.h"
#include "world/world.h"

namespace rm3d {

namespace {

WorldScript& script(lua_State* L) {
  return *static_cast<WorldScript*>(LuaVm::from(L)->user());
}
const World& world(lua_State* L) {
  return script(L).world();
}
WorldEditor& editor(lua_State* L) {
  return script(L).editor();
}

/// Bounds on settings: below or above these a run cannot make progress or cannot mean anything.
constexpr double kMinDt = 1e-6;              ///< s; also the shortest world.every period
constexpr double kMaxDt = 1.0;               ///< s
constexpr double kMaxGravity = 1e4;          ///< m/s^2 (1000 g)
constexpr double kMaxBounds = 1e7;           ///< m; single-precision positions out there are 1 m apart
constexpr double kRollingFriction = 0.0005;  ///< m: default rolling resistance of dynamic obstacles

/// world.set{solver=, dt=, substeps=, gravity={x,y,z}, seed=, duration=, solver_iterations=,
/// joint_iterations=, erp=, max_speed=, max_angular_speed=, bounds=, expect_faults=}
int worldSet(lua_State* L) {
  const char* fn = "world.set";
  checkOptionKeys(L, 1, fn,
                  {"solver", "dt", "substeps", "gravity", "seed", "duration", "solver_iterations",
                   "joint_iterations", "erp", "max_speed", "max_angular_speed", "bounds", "expect_faults"});
  WorldSettings s = world(L).settings();
  lua_getfield(L, 1, "solver");
  if (!lua_isnil(L, -1)) {
    const char* name = lua_type(L, -1) == LUA_TSTRING ? lua_tostring(L, -1) : nullptr;
    if (name && std::string_view(name) == "exact")
      s.solver = SolverKind::Exact;
    else if (name && std::string_view(name) == "pgs")
      s.solver = SolverKind::Pgs;
    else
      return luaL_error(L, "%s: solver must be \"exact\" or \"pgs\", got %s", fn,
                        name ? name : luaL_typename(L, -1));
  }
  lua_pop(L, 1);
  const double dt = optNumberField(L, 1, fn, "dt", s.dt);
  if (!(dt >= kMinDt && dt <= kMaxDt))
    return luaL_error(L, "%s: dt must be between %s and %s seconds, got %s", fn, numText(kMinDt).s,
                      numText(kMaxDt).s, numText(dt).s);
  const long long substeps = optIntegerField(L, 1, fn, "substeps", s.substeps);
  if (substeps < 1 || substeps > 1000)
    return luaL_error(L, "%s: substeps must be 1..1000, got %I", fn, (lua_Integer)substeps);
  const long long iters = optIntegerField(L, 1, fn, "solver_iterations", s.solverIterations);
  if (iters < 1 || iters > 10000)
    return luaL_error(L, "%s: solver_iterations must be 1..10000, got %I", fn, (lua_Integer)iters);
  const long long jiters = optIntegerField(L, 1, fn, "joint_iterations", s.jointIterations);
  if (jiters < 0 || jiters > 10000)
    return luaL_error(L, "%s: joint_iterations must be 0..10000, got %I", fn, (lua_Integer)jiters);
  const double erp = optNumberField(L, 1, fn, "erp", s.erp);
  if (erp <= 0 || erp > 1) return luaL_error(L, "%s: erp must be in (0, 1], got %s", fn, numText(erp).s);
  const double duration = optNumberField(L, 1, fn, "duration", s.duration);
  if (duration < 0)
    return luaL_error(L, "%s: duration must be 0 or more seconds, got %s", fn, numText(duration).s);
  const long long seed = optIntegerField(L, 1, fn, "seed", (long long)s.seed);
  if (seed < 0)
    return luaL_error(L, "%s: seed must be a whole number 0 or more, got %I", fn, (lua_Integer)seed);
  if (uint64_t(seed) != s.seed && !world(L).modules().empty())
    return luaL_error(L, "%s: set the seed before the first world.spawn", fn);
  const Vec3 gravity = optVec3Field(L, 1, fn, "gravity", s.gravity);
  if (!(gravity.norm() <= kMaxGravity))
    return luaL_error(L, "%s: gravity must be at most %s m/s^2 in magnitude (1000 g), got {%s, %s, %s}", fn,
                      numText(kMaxGravity).s, numText(gravity.x()).s, numText(gravity.y()).s,
                      numText(gravity.z()).s);
  DivergenceLimits lim = s.limits;
  lim.maxSpeed = optNumberField(L, 1, fn, "max_speed", lim.maxSpeed);
  if (lim.maxSpeed <= 0)
    return luaL_error(L, "%s: max_speed must be positive (m/s), got %s", fn, numText(lim.maxSpeed).s);
  lim.maxAngularSpeed = optNumberField(L, 1, fn, "max_angular_speed", lim.maxAngularSpeed);
  if (lim.maxAngularSpeed <= 0)
    return luaL_error(L, "%s: max_angular_speed must be positive (rad/s), got %s", fn,
                      numText(lim.maxAngularSpeed).s);
  lim.bounds = optNumberField(L, 1, fn, "bounds", lim.bounds);
  if (lim.bounds <= 0 || lim.bounds > kMaxBounds)
    return luaL_error(L, "%s: bounds must be in (0, %s] metres from the origin, got %s", fn,
                      numText(kMaxBounds).s, numText(lim.bounds).s);
  s.dt = dt;
  // Substeps and iterations not given follow the solver's defaults (a switch to "pgs" alone gets
  // the old solver as it was).
  s.substepsGiven = s.substepsGiven || hasField(L, 1, "substeps");
  s.iterationsGiven = s.iterationsGiven || hasField(L, 1, "solver_iterations");
  s.substeps = s.substepsGiven ? int(substeps) : defaultSubsteps(s.solver);
  s.solverIterations = s.iterationsGiven ? int(iters) : defaultIterations(s.solver);
  s.jointIterations = int(jiters);
  s.duration = duration;
  s.erp = erp;
  // --seed wins over world.set{seed=} (World::setSettings); math.random follows the one in force.
  const uint64_t effective = world(L).options().seed ? *world(L).options().seed : uint64_t(seed);
  if (effective != world(L).settings().seed) seedWorldRandom(L, effective);
  s.seed = uint64_t(seed);
  s.gravity = gravity;
  s.limits = lim;
  // expect_faults = true: the world faults modules on purpose; = n: exactly n modules fault.
  const int ef = lua_getfield(L, 1, "expect_faults");
  if (ef == LUA_TBOOLEAN) {
    script(L).expectFaults = lua_toboolean(L, -1) ? std::optional<int>(-1) : std::nullopt;
  } else if (ef != LUA_TNIL) {
    int isInt = 0;
    const lua_Integer n = ef == LUA_TNUMBER ? lua_tointegerx(L, -1, &isInt) : -1;
    if (!isInt || n < 0 || n > (1 << 30))
      return luaL_error(
          L, "%s: expect_faults must be true, false or a whole number of faulted modules (0 or more), got %s",
          fn, luaL_tolstring(L, -1, nullptr));
    script(L).expectFaults = int(n);
  }
  lua_pop(L, 1);
  editor(L).setSettings(s);
  return 0;
}

}  // namespace

void checkInBounds(lua_State* L, const char* fn, const Vec3& at) {
  const double bounds = world(L).settings().limits.bounds;
  if (!(at.norm() <= bounds))
    luaL_error(L,
               "%s: 'at' must lie within the world bounds (%s m from the origin; world.set{bounds=}), got "
               "{%s, %s, %s}",
               fn, numText(bounds).s, numText(at.x()).s, numText(at.y()).s, numText(at.z()).s);
}

namespace {

/// world.ground{friction=, restitution=}: the infinite plane z = 0
int worldGround(lua_State* L) {
  const char* fn = "world.ground";
  if (lua_isnoneornil(L, 1)) lua_newtable(L);
  checkOptionKeys(L, 1, fn, {"friction", "restitution"});
  const double friction = optNumberField(L, 1, fn, "friction", 0.8);
  const double restitution = optNumberField(L, 1, fn, "restitution", 0.0);
  if (friction < 0) return luaL_error(L, "%s: friction must not be negative", fn);
  if (!(restitution >= 0 && restitution <= 1))
    return luaL_error(L, "%s: restitution must be in [0, 1] (0: no bounce, 1: a full bounce), got %s", fn,
                      numText(restitution).s);
  return callWorld(L, fn, [&] {
    editor(L).addGround(friction, restitution);
    return 0;
  });
}

int addObstacle(lua_State* L, const char* fn, ShapeKind kind) {
  checkOptionKeys(L, 1, fn,
                  {"size", "radius", "length", "file", "scale", "concave", "at", "rot", "quat", "mass",
                   "friction", "rolling_friction", "velocity"});
  const bool concave = optBoolField(L, 1, fn, "concave", false);
  if (concave && kind != ShapeKind::Hull)
    return luaL_error(L, "%s: option 'concave' is world.mesh's (a static triangle mesh)", fn);
  if (concave) kind = ShapeKind::TriMesh;
  const Vec3 velocity = optVec3Field(L, 1, fn, "velocity", Vec3::Zero());
  const Pose pose = optPoseFields(L, 1, fn);
  checkInBounds(L, fn, pose.pos);
  const double mass = optNumberField(L, 1, fn, "mass", 0.0);
  const double friction = optNumberField(L, 1, fn, "friction", 0.8);
  if (mass < 0)
    return luaL_error(L, "%s: mass must not be negative (0 is static), got %s", fn, numText(mass).s);
  if (friction < 0)
    return luaL_error(L, "%s: friction must not be negative, got %s", fn, numText(friction).s);
  // A dynamic body's rolling resistance (m): a ball of radius r slows as on a surface of rolling
  // coefficient rolling_friction / r (0.0005 m: a 5 cm ball rolls to a stop like one on carpet).
  const double rolling = optNumberField(L, 1, fn, "rolling_friction", mass > 0 ? kRollingFriction : 0.0);
  if (!(rolling >= 0 && rolling <= 1))
    return luaL_error(L, "%s: rolling_friction must be 0 to 1 metres, got %s", fn, numText(rolling).s);
  const double maxSpeed = world(L).settings().limits.maxSpeed;
  if (!(velocity.norm() <= maxSpeed))
    return luaL_error(L, "%s: velocity must be at most max_speed (%s m/s; world.set{max_speed=}), got %s m/s",
                      fn, numText(maxSpeed).s, numText(velocity.norm()).s);
  const Vec3 size = optVec3Field(L, 1, fn, "size", Vec3(0.1, 0.1, 0.1));
  const double radius = optNumberField(L, 1, fn, "radius", 0.05);
  const double length = optNumberField(L, 1, fn, "length", 0.1);
  const double scale = optNumberField(L, 1, fn, "scale", 1.0);
  const char* file = optStringField(L, 1, fn, "file");
  const double bounds = world(L).settings().limits.bounds;
  auto bad = [&](double v) { return !(v > 0 && v <= bounds); };
  const char* range = "%s: %s must be positive and at most the world bounds (%s m), got %s";
  if (bad(size.minCoeff()) || bad(size.maxCoeff()))
    return luaL_error(L, "%s: size must be positive and at most the world bounds (%s m), got {%s, %s, %s}",
                      fn, numText(bounds).s, numText(size.x()).s, numText(size.y()).s, numText(size.z()).s);
  if (bad(radius)) return luaL_error(L, range, fn, "radius", numText(bounds).s, numText(radius).s);
  if (bad(length)) return luaL_error(L, range, fn, "length", numText(bounds).s, numText(length).s);
  if (bad(scale)) return luaL_error(L, range, fn, "scale", numText(bounds).s, numText(scale).s);
  const bool fromFile = kind == ShapeKind::Hull || kind == ShapeKind::TriMesh;
  if (fromFile && !file) return luaL_error(L, "%s: option 'file' (a mesh file) is required", fn);
  if (concave && (mass > 0 || velocity.squaredNorm() > 0))
    return luaL_error(L,
                      "%s: a concave mesh (concave = true) is static: leave out mass and velocity (for a "
                      "dynamic mesh use its convex hull, concave = false)",
                      fn);
  int part = -1;
  callWorld(L, fn, [&] {
    ShapeDef s;
    s.kind = kind;
    s.size = size;
    s.radius = radius;
    s.length = length;
    if (fromFile) loadMeshShape(world(L), file, scale, kind, s);
    part = editor(L).addObstacle(s, pose, mass, friction, rolling);
    if (mass > 0 && velocity.squaredNorm() > 0) editor(L).setPartVelocity(part, velocity);
    return 0;
  });
  pushBody(L, part);  // outside the try: pushing may raise a Lua error (a longjmp)
  return 1;
}

/// world.box{size={x,y,z}, at=, rot=, mass=, friction=, velocity=} -> Body (mass 0: static)
int worldBox(lua_State* L) {
  return addObstacle(L, "world.box", ShapeKind::Box);
}
/// world.sphere{radius=, at=, mass=, friction=} -> Body
int worldSphere(lua_State* L) {
  return addObstacle(L, "world.sphere", ShapeKind::Sphere);
}
/// world.cylinder{radius=, length=, at=, rot=, mass=, friction=} -> Body (axis along local z)
int worldCylinder(lua_State* L) {
  return addObstacle(L, "world.cylinder", ShapeKind::Cylinder);
}
/// world.capsule{radius=, length=, at=, rot=, mass=, friction=} -> Body (a cylinder of `length`
/// along local z with hemispherical caps: length + 2 radius overall)
int worldCapsule(lua_State* L) {
  return addObstacle(L, "world.capsule", ShapeKind::Capsule);
}
/// world.mesh{file=, scale=, concave=, at=, rot=, mass=, friction=} -> Body (the mesh's convex
/// hull; concave = true: the triangles themselves, static)
int worldMesh(lua_State* L) {
  return addObstacle(L, "world.mesh", ShapeKind::Hull);
}

/// Initial joint angles from world.spawn's `joints` option: {name = rad, ...} or {rad, rad, ...}
/// in the type's joint order. Throws InputError (inside callWorld).
std::vector<double> readJointAngles(lua_State* L, int index, const ModuleTypeDef& type) {
  std::vector<double> angles(type.joints.size(), 0.0);
  auto what = [&](size_t j) { return "joint '" + type.joints[j].name + "'"; };
  lua_pushnil(L);
  while (lua_next(L, index) != 0) {
    size_t j = type.joints.size();
    if (lua_type(L, -2) == LUA_TSTRING) {
      const std::string name = lua_tostring(L, -2);
      for (j = 0; j < type.joints.size() && type.joints[j].name != name; ++j) {
      }
      if (j == type.joints.size()) {
        std::string names;
        for (const JointDef& jd : type.joints) names += (names.empty() ? "" : ", ") + jd.name;
        lua_pop(L, 2);
        throw InputError("joints: " + type.name + " has no joint '" + name +
                         "' (its joints: " + (names.empty() ? "none" : names) + ")");
      }
    } else if (lua_isinteger(L, -2)) {
      const lua_Integer k = lua_tointeger(L, -2);
      if (k < 1 || k > lua_Integer(type.joints.size())) {
        lua_pop(L, 2);
        throw InputError("joints: index " + std::to_string(k) + " is out of range (" + type.name + " has " +
                         std::to_string(type.joints.size()) + " joints)");
      }
      j = size_t(k - 1);
    } else {
      lua_pop(L, 2);
      throw InputError("joints: keys must be joint names or indices 1.." +
                       std::to_string(type.joints.size()));
    }
    const bool number = lua_type(L, -1) == LUA_TNUMBER;
    const double a = number ? lua_tonumber(L, -1) : 0.0;
    lua_pop(L, 1);
    if (!number || !std::isfinite(a)) {
      lua_pop(L, 1);
      throw InputError("joints: " + what(j) + " must be a finite angle in radians");
    }
    const JointDef& jd = type.joints[j];
    if (jd.limited && (a < jd.lower - 1e-9 || a > jd.upper + 1e-9)) {
      lua_pop(L, 1);
      throw InputError("joints: " + what(j) + " angle " + std::to_string(a) + " is outside its limits " +
                       std::to_string(jd.lower) + ".." + std::to_string(jd.upper) + " rad");
    }
    angles[j] = a;
  }
  return angles;
}

/// The dock settings in the table at idx (world.docks, world.spawn's docks): raises a Lua error
/// naming `fn` and the key for a misspelled key or a bad value.
DockSettings readDockSettings(lua_State* L, int idx, const char* fn) {
  idx = lua_absindex(L, idx);
  checkOptionKeys(L, idx, fn,
                  {"capture", "capture_radius", "capture_angle", "latch_distance", "latch_angle",
                   "capture_speed", "capture_turn_speed", "capture_force", "capture_torque", "capture_time",
                   "pull", "strength", "strength_torque"});
  DockSettings d;
  if (const char* c = optStringField(L, idx, fn, "capture")) {
    if (std::string_view(c) == "joint")
      d.capture = DockDef::Capture::Joint;
    else if (std::string_view(c) == "magnet")
      d.capture = DockDef::Capture::Magnet;
    else
      luaL_error(L, "%s: capture must be \"joint\" or \"magnet\", got \"%s\"", fn, c);
  }
  for (const DockSettings::Field& f : DockSettings::kFields) {
    if (!hasField(L, idx, f.key)) continue;
    const double v = optNumberField(L, idx, fn, f.key, 0);
    if (!(v >= f.lo && v <= f.hi))
      luaL_error(L, "%s: %s must be %s to %s %s, got %s", fn, f.key, numText(f.lo).s, numText(f.hi).s, f.unit,
                 numText(v).s);
    d.*f.setting = v;
  }
  return d;
}

/// world.docks{capture=, capture_speed=, ...}: dock settings over the module types' for every
/// module spawned after the call (a key left out keeps the type's value)
int worldDocks(lua_State* L) {
  const char* fn = "world.docks";
  luaL_checktype(L, 1, LUA_TTABLE);
  const DockSettings d = readDockSettings(L, 1, fn);
  callWorld(L, fn, [&] {
    editor(L).setDockSettings(d);
    return 0;
  });
  return 0;
}

/// world.spawn(type, {at=, rot=, name=, behavior=, params=, fixed=, joints=}) -> Module; type is a
/// name in assets/modules or a path to a module-type file; fixed = true holds the root link in
/// place; joints = initial angles
int worldSpawn(lua_State* L) {
  const char* fn = "world.spawn";
  const char* type = luaL_checkstring(L, 1);
  if (lua_isnoneornil(L, 2)) {
    lua_settop(L, 1);
    lua_newtable(L);
  }
  checkOptionKeys(
      L, 2, fn, {"at", "rot", "quat", "name", "behavior", "behaviour", "params", "fixed", "joints", "docks"});
  const bool fixed = optBoolField(L, 2, fn, "fixed", false);
  DockSettings docks;
  {
    const int t = lua_getfield(L, 2, "docks");
    if (t != LUA_TNIL && t != LUA_TTABLE)
      return luaL_error(L, "%s: option 'docks' must be a table of dock settings (as world.docks takes)", fn);
    if (t == LUA_TTABLE) docks = readDockSettings(L, -1, "world.spawn: docks");
    lua_pop(L, 1);
  }
  const Pose pose = optPoseFields(L, 2, fn);
  checkInBounds(L, fn, pose.pos);
  const char* name = optStringField(L, 2, fn, "name");
  const char* behaviour = optStringField(L, 2, fn, "behavior");
  if (!behaviour) behaviour = optStringField(L, 2, fn, "behaviour");
  const int jointsType = lua_getfield(L, 2, "joints");
  if (jointsType != LUA_TNIL && jointsType != LUA_TTABLE)
    return luaL_error(L, "%s: option 'joints' must be a table of angles (by joint name or in joint order)",
                      fn);
  const int jointsIndex = lua_gettop(L);
  const int paramsType = lua_getfield(L, 2, "params");
  if (paramsType != LUA_TNIL && paramsType != LUA_TTABLE)
    return luaL_error(L, "%s: option 'params' must be a table", fn);
  int spawned = -1;
  callWorld(L, fn, [&] {
    World::SpawnDef def;
    def.type = type;
    if (jointsType == LUA_TTABLE) def.joints = readJointAngles(L, jointsIndex, editor(L).moduleType(type));
    def.pose = pose;
    def.fixed = fixed;
    def.docks = docks;
    if (name) def.name = name;
    if (behaviour) def.behaviour = behaviour;
    std::string err;
    if (paramsType == LUA_TTABLE && !readLuaValue(L, -1, def.params, kParamsLimit, err))
      throw InputError("params: " + err);
    for (const Module& m : world(L).modules())
      if (!def.name.empty() && m.name == def.name)
        throw InputError("a module named '" + def.name + "' exists already");
    spawned = editor(L).spawn(def);
    return 0;
  });
  pushModule(L, spawned);  // outside the try: pushing may raise a Lua error (a longjmp)
  return 1;
}

/// world.connect(a, dock_a, b, dock_b [, orientation 0..3]): place b so the docks mate, lock them
int worldConnect(lua_State* L) {
  const char* fn = "world.connect";
  const int a = checkModule(L, 1);
  const int da = checkDockName(L, 2, a);
  const int b = checkModule(L, 3);
  const int db = checkDockName(L, 4, b);
  const int orientation = int(luaL_optinteger(L, 5, 0));
  return callWorld(L, fn, [&] {
    editor(L).connect(a, da, b, db, orientation);
    return 0;
  });
}

/// world.place_facing(a, dock_a, b, dock_b [, gap [, orientation]]): places b (and what is docked
/// to it) so its dock faces a's squarely, `gap` metres (default 0.01) out along a's normal, turned
/// orientation x 360/symmetry degrees about it; nothing is locked
int worldPlaceFacing(lua_State* L) {
  const char* fn = "world.place_facing";
  const int a = checkModule(L, 1);
  const int da = checkDockName(L, 2, a);
  const int b = checkModule(L, 3);
  const int db = checkDockName(L, 4, b);
  const double gap = luaL_optnumber(L, 5, 0.01);
  if (!(gap >= 0 && gap <= 10))
    return luaL_error(L, "%s: the gap must be 0 to 10 metres, got %s", fn, numText(gap).s);
  const int orientation = int(luaL_optinteger(L, 6, 0));
  return callWorld(L, fn, [&] {
    editor(L).placeFacing(a, da, b, db, gap, orientation);
    return 0;
  });
}

/// world.place_on_ground(m [, z]) -> how far it moved: m's connected component moves straight
/// down (or up) until its lowest point is at height z (default 0, the ground plane)
int worldPlaceOnGround(lua_State* L) {
  const char* fn = "world.place_on_ground";
  const int m = checkModule(L, 1);
  const double z = luaL_optnumber(L, 2, 0.0);
  if (!std::isfinite(z)) return luaL_error(L, "%s: the height must be a finite number of metres", fn);
  checkInBounds(L, fn, Vec3(0, 0, z));
  double moved = 0;
  callWorld(L, fn, [&] {
    moved = editor(L).placeOnGround(m, z);
    return 0;
  });
  lua_pushnumber(L, moved);
  return 1;
}

/// world.camera{eye={x,y,z}, target={x,y,z}, follow=module, fov=degrees}: the picture's view;
/// with `follow`, the camera looks at that module and `eye` is an offset from it
int worldCamera(lua_State* L) {
  const char* fn = "world.camera";
  checkOptionKeys(L, 1, fn, {"eye", "target", "follow", "fov"});
  World::CameraDef c;
  if (lua_getfield(L, 1, "eye") != LUA_TNIL) c.eye = optVec3Field(L, 1, fn, "eye", Vec3::Zero());
  if (lua_getfield(L, 1, "target") != LUA_TNIL) c.target = optVec3Field(L, 1, fn, "target", Vec3::Zero());
  if (lua_getfield(L, 1, "follow") != LUA_TNIL) c.follow = checkModule(L, -1);
  lua_pop(L, 3);
  c.fovDeg = optNumberField(L, 1, fn, "fov", 45.0);
  if (c.fovDeg <= 1 || c.fovDeg >= 170) return luaL_error(L, "%s: fov must be between 1 and 170 degrees", fn);
  if (c.follow >= 0 && !c.eye) c.eye = Vec3(0.6, -1.0, 0.6);
  editor(L).setCamera(c);
  return 0;
}

/// world.channel{loss=, delay=, rate=, max_bytes=}: how messages travel over connections
int worldChannel(lua_State* L) {
  const char* fn = "world.channel";
  checkOptionKeys(L, 1, fn, {"loss", "delay", "rate", "max_bytes"});
  ChannelDef c = world(L).channel();
  c.loss = optNumberField(L, 1, fn, "loss", c.loss);
  if (c.loss < 0 || c.loss > 1) return luaL_error(L, "%s: loss must be a probability in [0, 1]", fn);
  const long long delay = optIntegerField(L, 1, fn, "delay", c.delay);
  const long long rate = optIntegerField(L, 1, fn, "rate", c.rate);
  const long long bytes = optIntegerField(L, 1, fn, "max_bytes", (long long)c.maxBytes);
  if (delay < 0 || delay > 1000000) return luaL_error(L, "%s: delay must be 0 or more steps", fn);
  if (rate < 0) return luaL_error(L, "%s: rate must be 0 (unlimited) or more messages per step", fn);
  if (bytes < 16) return luaL_error(L, "%s: max_bytes must be at least 16", fn);
  c.delay = int(delay);
  c.rate = int(rate);
  c.maxBytes = size_t(bytes);
  editor(L).setChannel(c);
  return 0;
}

/// world.graph([format]) -> the connection graph now, as "json" (default) or "dot" text
int worldGraph(lua_State* L) {
  static const char* const formats[] = {"json", "dot", nullptr};
  const int f = luaL_checkoption(L, 1, "json", formats);
  // The text leaves the try in a plain buffer (no destructor for a Lua error's longjmp to skip;
  // should pushing fail for want of memory, only the buffer is lost).
  char* copy = nullptr;
  size_t size = 0;
  callWorld(L, "world.graph", [&] {
    const std::string text = f == 0 ? graphJson(world(L)) : graphDot(world(L));
    size = text.size();
    copy = new char[size + 1];
    std::memcpy(copy, text.data(), size);
    return 0;
  });
  lua_pushlstring(L, copy, size);
  delete[] copy;
  return 1;
}

/// world.events([since]) -> array of {time=, event=, module_a=, dock_a=, module_b=, dock_b=,
/// force=, torque=, distance=, angle=} dock events (engaged, disengaged, broken, captured,
/// stalled; loads for broken, what is left to close for stalled), optionally only those at or
/// after time `since`
int worldEvents(lua_State* L) {
  const double since = luaL_optnumber(L, 1, -1.0);
  const World& w = world(L);
  lua_newtable(L);
  lua_Integer n = 0;
  for (const DockEvent& e : w.events()) {
    if (e.time < since) continue;
    const Module& a = w.module(e.moduleA);
    const Module& b = w.module(e.moduleB);
    lua_createtable(L, 0, 8);
    lua_pushnumber(L, e.time);
    lua_setfield(L, -2, "time");
    lua_pushstring(L, dockEventName(e.kind));
    lua_setfield(L, -2, "event");
    lua_pushinteger(L, a.id);
    lua_setfield(L, -2, "module_a");
    lua_pushstring(L, a.type->docks[size_t(e.dockA)].name.c_str());
    lua_setfield(L, -2, "dock_a");
    lua_pushinteger(L, b.id);
    lua_setfield(L, -2, "module_b");
    lua_pushstring(L, b.type->docks[size_t(e.dockB)].name.c_str());
    lua_setfield(L, -2, "dock_b");
    if (e.force >= 0) {
      lua_pushnumber(L, e.force);
      lua_setfield(L, -2, "force");
      lua_pushnumber(L, e.torque);
      lua_setfield(L, -2, "torque");
    }
    if (e.gap >= 0) {  // a stalled capture: what it has left to close
      lua_pushnumber(L, e.gap);
      lua_setfield(L, -2, "distance");
      lua_pushnumber(L, e.angle);
      lua_setfield(L, -2, "angle");
    }
    lua_rawseti(L, -2, ++n);
  }
  return 1;
}

/// world.messages() -> {sent=, received=, dropped=}: message counts over the run so far
int worldMessages(lua_State* L) {
  const World::MessageStats st = world(L).messageStats();
  lua_createtable(L, 0, 3);
  lua_pushinteger(L, lua_Integer(st.sent));
  lua_setfield(L, -2, "sent");
  lua_pushinteger(L, lua_Integer(st.received));
  lua_setfield(L, -2, "received");
  lua_pushinteger(L, lua_Integer(st.dropped));
  lua_setfield(L, -2, "dropped");
  return 1;
}

/// world.modules() -> array of Module handles, in id order
int worldModules(lua_State* L) {
  const int n = int(world(L).modules().size());
  lua_createtable(L, n, 0);
  for (int i = 0; i < n; ++i) {
    pushModule(L, i);
    lua_rawseti(L, -2, i + 1);
  }
  return 1;
}

/// world.module(id or name) -> Module or nil
int worldModule(lua_State* L) {
  const auto& mods = world(L).modules();
  if (lua_type(L, 1) == LUA_TNUMBER) {
    const lua_Integer id = luaL_checkinteger(L, 1);
    if (id >= 1 && id <= lua_Integer(mods.size())) {
      pushModule(L, int(id - 1));
      return 1;
    }
    return 0;
  }
  const char* name = luaL_checkstring(L, 1);
  for (size_t i = 0; i < mods.size(); ++i)
    if (mods[i].name == name) {
      pushModule(L, int(i));
      return 1;
    }
  return 0;
}

/// world.module_type(name) -> the type's data (links, joints, docks; script/module_type_data.h)
int worldModuleType(lua_State* L) {
  const char* name = luaL_checkstring(L, 1);
  const ModuleTypeDef* type = nullptr;
  callWorld(L, "world.module_type", [&] {
    type = &editor(L).moduleType(name);
    return 0;
  });
  pushModuleTypeData(L, *type);
  return 1;
}

/// world.components() -> array of arrays of Module handles (connected by docks)
int worldComponents(lua_State* L) {
  const auto comps = world(L).components();
  lua_createtable(L, int(comps.size()), 0);
  for (size_t c = 0; c < comps.size(); ++c) {
    lua_createtable(L, int(comps[c].size()), 0);
    for (size_t k = 0; k < comps[c].size(); ++k) {
      pushModule(L, comps[c][k]);
      lua_rawseti(L, -2, lua_Integer(k + 1));
    }
    lua_rawseti(L, -2, lua_Integer(c + 1));
  }
  return 1;
}

/// "file:line:" of the Lua code calling the current C function.
std::string where(lua_State* L) {
  luaL_where(L, 1);
  std::string w = lua_tostring(L, -1);
  lua_pop(L, 1);
  return w;
}

int storeFunction(lua_State* L, int arg) {
  luaL_checktype(L, arg, LUA_TFUNCTION);
  lua_pushvalue(L, arg);
  return luaL_ref(L, LUA_REGISTRYINDEX);
}

/// world.on_step(fn(t)): called after every step
int worldOnStep(lua_State* L) {
  script(L).onStep.push_back(storeFunction(L, 1));
  return 0;
}

/// world.at(t, fn(t)): called once, after the first step that reaches time t
int worldAt(lua_State* L) {
  const double t = luaL_checknumber(L, 1);
  if (!(t >= 0 && std::isfinite(t)))
    return luaL_error(L, "world.at: time must be a finite number of seconds >= 0, got %s", numText(t).s);
  const int ref = storeFunction(L, 2);
  script(L).timed.push_back({t, 0.0, ref, where(L), t, 0});
  return 0;
}

/// world.every(period, fn(t)): called at t = period, 2 period, ...; a period shorter than dt
/// calls fn once per step. The period must be at least 1e-6 s (the shortest dt): whichever order
/// world.set and world.every come in, a hook can always catch up.
int worldEvery(lua_State* L) {
  const double p = luaL_checknumber(L, 1);
  if (!(p >= kMinDt && std::isfinite(p)))
    return luaL_error(L, "world.every: period must be a finite number of seconds >= %s, got %s",
                      numText(kMinDt).s, numText(p).s);
  const int ref = storeFunction(L, 2);
  script(L).timed.push_back({p, p, ref, where(L), p, 0});
  return 0;
}

/// world.on_end(fn(t)): called once when the run ends, however it ends (duration, world.stop(),
/// --seconds/--steps, Ctrl-C): the place for checks that must run whatever the run's length
int worldOnEnd(lua_State* L) {
  script(L).onEnd.push_back(storeFunction(L, 1));
  return 0;
}

/// Stores the function at arg 1 in `ref` (a registry reference), replacing the one before.
int replaceHook(lua_State* L, int& ref) {
  const int fn = storeFunction(L, 1);
  if (ref >= 0) luaL_unref(L, LUA_REGISTRYINDEX, ref);
  ref = fn;
  return 0;
}

/// world.reward(fn(t)): for the Python API (docs/python.md): fn returns a number (every module
/// gets it) or a list with one number per module, read after each step into the reward array
int worldReward(lua_State* L) {
  return replaceHook(L, script(L).rewardRef);
}

/// world.done(fn(t)): for the Python API: fn returns a boolean (every module) or a list with one
/// per module, read after each step into the done array
int worldDone(lua_State* L) {
  return replaceHook(L, script(L).doneRef);
}

/// world.trace(name, value): records a series for `rm3d run --trace` (column trace.<name> of the
/// world's rows) and the viewer; name: letters, digits, _ . -; value: a finite number
int worldTrace(lua_State* L) {
  return recordSeries(L, editor(L).worldTraces(), "world.trace", "the world script");
}

/// world.metric(name, value): a named result, under "metrics" in the --json summary (a later
/// call with the same name replaces the value)
int worldMetric(lua_State* L) {
  const char* name = checkSeriesName(L, 1, "world.metric");
  const double v = checkSeriesValue(L, 2, "world.metric");
  WorldEditor& w = editor(L);
  if (w.view().metrics().size() >= World::kMaxMetrics && !w.view().metrics().count(name))
    return luaL_error(L, "world.metric: too many metrics (at most %d); '%s' is one more",
                      int(World::kMaxMetrics), name);
  return callWorld(L, "world.metric", [&] {
    w.setMetric(name, v);
    return 0;
  });
}

/// world.stop(): end the run after this step
int worldStop(lua_State* L) {
  editor(L).requestStop();
  return 0;
}

/// world.time() -> seconds
int worldTime(lua_State* L) {
  lua_pushnumber(L, world(L).time());
  return 1;
}

/// world.dt() -> the control step
int worldDt(lua_State* L) {
  lua_pushnumber(L, world(L).settings().dt);
  return 1;
}

/// expect(cond, message) -> cond: a failed expectation is recorded with file:line; the run goes on
int expectFn(lua_State* L) {
  luaL_checkany(L, 1);
  ++script(L).expectCount;
  const bool ok = lua_toboolean(L, 1);
  if (!ok) {
    luaL_where(L, 1);
    if (lua_isnoneornil(L, 2))
      lua_pushliteral(L, "expectation failed");
    else
      luaL_tolstring(L, 2, nullptr);
    lua_concat(L, 2);
    editor(L).addFailure(lua_tostring(L, -1));
    lua_pop(L, 1);
  }
  lua_pushboolean(L, ok);
  return 1;
}

/// log(...) / print(...) in the world script
int worldLog(lua_State* L) {
  const int n = lua_gettop(L);
  luaL_Buffer b;
  luaL_buffinit(L, &b);
  for (int i = 1; i <= n; ++i) {
    luaL_tolstring(L, i, nullptr);
    luaL_addvalue(&b);
    if (i < n) luaL_addchar(&b, '\t');
  }
  luaL_pushresult(&b);
  if (world(L).options().echoWorldLog)
    std::fprintf(stderr, "[%8.3f world] %s\n", world(L).time(), lua_tostring(L, -1));
  return 0;
}

void pushArgs(lua_State* L, const std::map<std::string, std::string>& params) {
  lua_newtable(L);
  for (const auto& [k, v] : params) {
    // Numbers and booleans arrive typed, so `args.n or 10` works as expected.
    const ParamValue p = parseParamValue(v);
    switch (p.kind) {
      case ParamValue::Kind::Integer:
        lua_pushinteger(L, p.integer);
        break;
      case ParamValue::Kind::Number:
        lua_pushnumber(L, p.number);
        break;
      case ParamValue::Kind::Boolean:
        lua_pushboolean(L, p.boolean);
        break;
      case ParamValue::Kind::String:
        lua_pushstring(L, v.c_str());
        break;
    }
    lua_setfield(L, -2, k.c_str());
  }
}

}  // namespace

const World& scriptWorld(lua_State* L) {
  return script(L).world();
}
WorldEditor& scriptEditor(lua_State* L) {
  return script(L).editor();
}

void seedWorldRandom(lua_State* L, uint64_t seed) {
  lua_getglobal(L, "math");
  if (lua_getfield(L, -1, "randomseed") == LUA_TFUNCTION) {
    lua_pushinteger(L, lua_Integer(seed));
    lua_call(L, 1, 0);
  } else {
    lua_pop(L, 1);
  }
  lua_pop(L, 1);
}

void openWorldApi(lua_State* L, WorldScript& s) {
  openModuleHandle(L);
  openBodyHandle(L);
  openClothHandle(L);
  openHeightfieldHandle(L);
  static const luaL_Reg fns[] = {{"set", worldSet},
                                 {"ground", worldGround},
                                 {"heightfield", worldHeightfield},
                                 {"box", worldBox},
                                 {"sphere", worldSphere},
                                 {"cylinder", worldCylinder},
                                 {"capsule", worldCapsule},
                                 {"mesh", worldMesh},
                                 {"spawn", worldSpawn},
                                 {"place_on_ground", worldPlaceOnGround},
                                 {"place_facing", worldPlaceFacing},
                                 {"docks", worldDocks},
                                 {"connect", worldConnect},
                                 {"modules", worldModules},
                                 {"module", worldModule},
                                 {"components", worldComponents},
                                 {"module_type", worldModuleType},
                                 {"camera", worldCamera},
                                 {"channel", worldChannel},
                                 {"graph", worldGraph},
                                 {"events", worldEvents},
                                 {"messages", worldMessages},
                                 {"on_step", worldOnStep},
                                 {"on_end", worldOnEnd},
                                 {"reward", worldReward},
                                 {"done", worldDone},
                                 {"at", worldAt},
                                 {"every", worldEvery},
                                 {"stop", worldStop},
                                 {"time", worldTime},
                                 {"dt", worldDt},
                                 {"metric", worldMetric},
                                 {nullptr, nullptr}};
  luaL_newlib(L, fns);
  openParticleApi(L);
  pushSeriesClosure(L, worldTrace);
  lua_setfield(L, -2, "trace");
  lua_pushcfunction(L, worldCloth);  // world.cloth{...}: world_cloth.cpp
  lua_setfield(L, -2, "cloth");
  lua_setglobal(L, "world");
  lua_pushcfunction(L, expectFn);
  lua_setglobal(L, "expect");
  lua_pushcfunction(L, worldLog);
  lua_setglobal(L, "log");
  lua_pushcfunction(L, worldLog);
  lua_setglobal(L, "print");
  pushArgs(L, s.world().options().params);
  lua_setglobal(L, "args");
}

}  // namespace rm3d
