// Module-type loading in two steps. First the file runs in a sandboxed LuaVm and the table it
// returns is copied into a plain C++ tree (messaging/value.h, by script/lua_value's copier) using
// only Lua API calls that never raise (lua_next, lua_type, lua_to*): a Lua error longjmps and
// would skip the destructors of the C++ objects alive here. Then that tree is validated and converted in
// ordinary C++, with errors thrown as InputError that name the file and the place in the data
// ("links[2].shapes[1]: ...").
#include "script/module_type_loader.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <initializer_list>
#include <lua.hpp>
#include <map>
#include <utility>

#include "assets/mesh_loader.h"
#include "core/error.h"
#include "core/path_rule.h"
#include "script/lua_value.h"
#include "script/lua_vm.h"

namespace fs = std::filesystem;

namespace rm3d {

namespace {

/// Largest size, mass or other magnitude a module type may give (SI units); beyond it the
/// physics cannot mean anything.
constexpr double kMaxMagnitude = 1e6;
/// Shapes per link: a link is a rigid body, and each shape is tested in every contact pair.
constexpr size_t kMaxShapesPerLink = 256;

constexpr size_t kMemoryLimit = size_t(64) << 20;
constexpr int64_t kInstructionBudget = 100000000;
// Module types nest four levels deep; anything far deeper is a mistake, and the limit keeps the
// recursive copy from running out of C++ stack.
constexpr int kMaxDepth = 32;
// Below this length a direction (axis, normal, up) is taken to be zero.
constexpr double kMinDirection = 1e-9;
// A given `up` must be this close to perpendicular to the dock normal (cosine of the angle).
constexpr double kPerpendicularTol = 1e-6;
// When the dock normal is this close to z, the default `up` is x projected instead of z.
constexpr double kNearZ = 0.9;

std::string formatNumber(double x) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.10g", x);
  return buf;
}

std::string childPath(const std::string& where, const std::string& key) {
  return where.empty() ? key : where + "." + key;
}

std::string indexPath(const std::string& where, int64_t i) {
  return where + "[" + std::to_string(i) + "]";
}

bool isNumber(const Value& v) {
  return v.type == Value::Type::Integer || v.type == Value::Type::Number;
}

double numberOf(const Value& v) {
  return v.type == Value::Type::Integer ? double(v.integer) : v.number;
}

/// A number with an integer value (integer subtype or integral float).
bool isIntegral(const Value& v) {
  return v.type == Value::Type::Integer ||
         (v.type == Value::Type::Number && std::isfinite(v.number) && v.number == std::floor(v.number));
}

bool isIndex(const Value& key) {
  return key.type == Value::Type::Integer;
}

/// What a value is, for "expected X, got Y" messages.
std::string describe(const Value& v) {
  switch (v.type) {
    case Value::Type::Nil:
      return "nil";
    case Value::Type::Boolean:
      return v.boolean ? "true" : "false";
    case Value::Type::Integer:
    case Value::Type::Number:
      return "the number " + formatNumber(numberOf(v));
    case Value::Type::String:
      return "the string '" + v.string + "'";
    case Value::Type::Table: {
      std::string names;
      for (const auto& [key, value] : v.table)
        if (!isIndex(key)) names += (names.empty() ? "" : ", ") + key.string;
      if (!names.empty()) return "a table with named fields (" + names + ")";
      return v.table.empty() ? "an empty table" : "a list of " + std::to_string(v.table.size()) + " values";
    }
    case Value::Type::Opaque:
      return v.string == "function" ? "a function" : "a value of an unsupported type";
  }
  return "a value of an unsupported type";
}

/// Copies the value at a stack index with the shared copier (which never raises: a Lua error
/// would longjmp past the C++ objects alive here) and throws its failure as an InputError.
Value copyModuleTable(lua_State* L, int idx, const std::string& file) {
  LuaValueOptions options;
  options.maxDepth = kMaxDepth;
  options.keepOpaque = true;
  options.plainKeys = true;
  LuaValueError err;
  Value out;
  if (readLuaValue(L, idx, out, options, err)) return out;
  std::string where;
  for (const LuaPathStep& step : err.path)
    where = step.isIndex ? indexPath(where, step.index) : childPath(where, step.name);
  std::string msg;
  switch (err.kind) {
    case LuaValueError::Kind::TooDeep:
      msg = "tables nested too deeply";
      break;
    case LuaValueError::Kind::Cycle:
      msg = "a table that contains itself";
      break;
    case LuaValueError::Kind::NoStack:
      msg = "out of Lua stack space";
      break;
    case LuaValueError::Kind::BadKey:
      msg = (err.typeName == "number" ? "unexpected key " + formatNumber(err.number)
                                      : "unexpected key of type " + err.typeName) +
            " (keys are names or list positions 1, 2, ...)";
      break;
    default:  // not made with these options
      msg = "cannot be copied";
      break;
  }
  throw InputError(file + ": " + (where.empty() ? "" : where + ": ") + msg);
}

/// Validates the copied tree and builds the ModuleTypeDef.
class TypeReader {
 public:
  TypeReader(const LuaVm& vm, std::string file, fs::path dir, fs::path root, MeshCache* meshes)
      : m_vm(vm), m_file(std::move(file)), m_dir(std::move(dir)), m_root(std::move(root)), m_cache(meshes) {}

  ModuleTypeDef read(const Value& top) {
    if (top.type != Value::Type::Table)
      fail("",
           "expected the file to return a table { name = ..., links = { ... }, ... }, got " + describe(top));
    checkRecord(top, "", {"name", "root", "links", "joints", "docks", "sensors"});
    ModuleTypeDef def;
    def.name = toName(require(top, "", "name"), "name");
    def.file = m_file;

    const auto links = toList(require(top, "", "links"), "links");
    if (links.empty()) fail("links", "a module type needs at least one link");
    for (size_t i = 0; i < links.size(); ++i)
      def.links.push_back(readLink(*links[i], indexPath("links", i + 1)));
    checkUnique(def.links, "links", "link");

    def.rootLink = 0;
    if (const Value* r = find(top, "root")) def.rootLink = linkIndex(def, *r, "root");

    if (const Value* js = find(top, "joints")) {
      const auto joints = toList(*js, "joints");
      for (size_t i = 0; i < joints.size(); ++i)
        def.joints.push_back(readJoint(def, *joints[i], indexPath("joints", i + 1)));
      checkUnique(def.joints, "joints", "joint");
    }
    if (const Value* ds = find(top, "docks")) {
      const auto docks = toList(*ds, "docks");
      for (size_t i = 0; i < docks.size(); ++i)
        def.docks.push_back(readDock(def, *docks[i], indexPath("docks", i + 1)));
      checkUnique(def.docks, "docks", "dock");
    }
    if (const Value* ss = find(top, "sensors")) {
      const auto sensors = toList(*ss, "sensors");
      for (size_t i = 0; i < sensors.size(); ++i)
        def.sensors.push_back(readSensor(def, *sensors[i], indexPath("sensors", i + 1)));
      checkUnique(def.sensors, "sensors", "sensor");
    }
    checkConnected(def);
    return def;
  }

 private:
  [[noreturn]] void fail(const std::string& where, const std::string& msg) const {
    throw InputError(m_file + ": " + (where.empty() ? "" : where + ": ") + msg);
  }

  // ---- generic checks on the copied values ----

  static const Value* find(const Value& rec, const char* key) {
    for (const auto& [k, value] : rec.table)
      if (k.type == Value::Type::String && k.string == key) return &value;
    return nullptr;
  }

  const Value& require(const Value& rec, const std::string& where, const char* key) const {
    const Value* v = find(rec, key);
    if (v == nullptr) fail(where, std::string("missing required field '") + key + "'");
    return *v;
  }

  /// A table of named fields, each one of `allowed`.
  void checkRecord(const Value& v, const std::string& where,
                   std::initializer_list<const char*> allowed) const {
    std::string expected;
    for (const char* k : allowed) expected += std::string(expected.empty() ? "" : ", ") + k;
    if (v.type != Value::Type::Table)
      fail(where, "expected a table with fields " + expected + ", got " + describe(v));
    for (const auto& entry : v.table) {
      const Value& k = entry.first;  // not a structured binding: the lambda below captures it
      if (isIndex(k))
        fail(where, "unexpected list entry [" + std::to_string(k.integer) +
                        "] (expected named fields: " + expected + ")");
      if (std::none_of(allowed.begin(), allowed.end(), [&](const char* name) { return k.string == name; }))
        fail(where, "unknown key '" + k.string + "' (expected one of: " + expected + ")");
    }
  }

  /// A list {a, b, c}: integer keys 1..n only.
  std::vector<const Value*> toList(const Value& v, const std::string& where) const {
    if (v.type != Value::Type::Table) fail(where, "expected a list { ... }, got " + describe(v));
    std::vector<const Value*> out;
    for (const auto& [k, value] : v.table) {
      if (!isIndex(k)) fail(where, "unexpected named field '" + k.string + "' in a list");
      if (k.integer != int64_t(out.size()) + 1)
        fail(where, "list has a gap or bad position [" + std::to_string(k.integer) + "] (expected [" +
                        std::to_string(out.size() + 1) + "])");
      out.push_back(&value);
    }
    return out;
  }

  double toNumber(const Value& v, const std::string& where) const {
    if (!isNumber(v)) fail(where, "expected a number, got " + describe(v));
    const double x = numberOf(v);
    if (!std::isfinite(x)) fail(where, "expected a finite number, got " + formatNumber(x));
    return x;
  }

  double toNonNegative(const Value& v, const std::string& where) const {
    const double x = toNumber(v, where);
    if (x < 0) fail(where, "must not be negative (got " + formatNumber(x) + ")");
    return x;
  }

  double toPositive(const Value& v, const std::string& where) const {
    const double x = toNumber(v, where);
    if (x <= 0) fail(where, "must be greater than 0 (got " + formatNumber(x) + ")");
    if (x > kMaxMagnitude)
      fail(where, "must be at most " + formatNumber(kMaxMagnitude) + " (got " + formatNumber(x) + ")");
    return x;
  }

  bool toBool(const Value& v, const std::string& where) const {
    if (v.type != Value::Type::Boolean) fail(where, "expected true or false, got " + describe(v));
    return v.boolean;
  }

  std::string toString(const Value& v, const std::string& where) const {
    if (v.type != Value::Type::String) fail(where, "expected a string, got " + describe(v));
    return v.string;
  }

  std::string toName(const Value& v, const std::string& where) const {
    std::string s = toString(v, where);
    if (s.empty()) fail(where, "name must not be empty");
    return s;
  }

  /// A list of between minCount and maxCount numbers; `shape` describes it for messages.
  std::vector<double> toNumbers(const Value& v, const std::string& where, size_t minCount, size_t maxCount,
                                const std::string& shape) const {
    bool ok = v.type == Value::Type::Table;
    if (ok) {
      for (size_t i = 0; i < v.table.size(); ++i) {
        const auto& [k, value] = v.table[i];
        ok = ok && isIndex(k) && k.integer == int64_t(i) + 1 && isNumber(value);
      }
      ok = ok && v.table.size() >= minCount && v.table.size() <= maxCount;
    }
    if (!ok) fail(where, "expected " + shape + ", got " + describe(v));
    std::vector<double> out;
    for (size_t i = 0; i < v.table.size(); ++i)
      out.push_back(toNumber(v.table[i].second, indexPath(where, i + 1)));
    return out;
  }

  Vec3 toVec3(const Value& v, const std::string& where) const {
    const auto n = toNumbers(v, where, 3, 3, "{x, y, z} (3 numbers)");
    return Vec3(n[0], n[1], n[2]);
  }

  /// A direction: normalised silently, zero rejected.
  Vec3 toDirection(const Value& v, const std::string& where) const {
    const Vec3 d = toVec3(v, where);
    if (d.norm() < kMinDirection) fail(where, "direction must not be zero");
    return d.normalized();
  }

  template <class T>
  void checkUnique(const std::vector<T>& items, const std::string& list, const char* what) const {
    std::map<std::string, size_t> seen;
    for (size_t i = 0; i < items.size(); ++i) {
      const auto [it, fresh] = seen.emplace(items[i].name, i);
      if (!fresh)
        fail(childPath(indexPath(list, i + 1), "name"), std::string("duplicate ") + what + " name '" +
                                                            items[i].name + "' (also " +
                                                            indexPath(list, it->second + 1) + ")");
    }
  }

  int linkIndex(const ModuleTypeDef& def, const Value& v, const std::string& where) const {
    const std::string name = toName(v, where);
    const int i = def.findLink(name);
    if (i < 0) {
      std::string names;
      for (const LinkDef& l : def.links) names += (names.empty() ? "" : ", ") + l.name;
      fail(where, "unknown link '" + name + "' (links are: " + names + ")");
    }
    return i;
  }

  // ---- module-type parts ----

  LinkDef readLink(const Value& v, const std::string& where) {
    checkRecord(v, where, {"name", "mass", "color", "friction", "rolling_friction", "shapes", "collision"});
    LinkDef link;
    link.name = toName(require(v, where, "name"), childPath(where, "name"));
    link.mass = toPositive(require(v, where, "mass"), childPath(where, "mass"));
    if (const Value* c = find(v, "color")) {
      const std::string w = childPath(where, "color");
      const auto rgba = toNumbers(*c, w, 3, 4, "{r, g, b} or {r, g, b, a} (numbers from 0 to 1)");
      for (size_t i = 0; i < rgba.size(); ++i) {
        if (rgba[i] < 0 || rgba[i] > 1)
          fail(indexPath(w, i + 1), "must be between 0 and 1 (got " + formatNumber(rgba[i]) + ")");
        link.color[i] = float(rgba[i]);
      }
    }
    if (const Value* f = find(v, "friction")) link.friction = toNonNegative(*f, childPath(where, "friction"));
    if (const Value* f = find(v, "rolling_friction")) {
      const std::string w = childPath(where, "rolling_friction");
      link.rollingFriction = toNonNegative(*f, w);
      if (link.rollingFriction > 0.1)
        fail(w, "must be at most 0.1 m (a lever arm; got " + formatNumber(link.rollingFriction) + ")");
    }
    const std::string ws = childPath(where, "shapes");
    const auto shapes = toList(require(v, where, "shapes"), ws);
    if (shapes.empty()) fail(ws, "a link needs at least one shape");
    if (shapes.size() > kMaxShapesPerLink)
      fail(ws, "a link has at most " + std::to_string(kMaxShapesPerLink) + " shapes (got " +
                   std::to_string(shapes.size()) + ")");
    double fixedMass = 0;
    for (size_t i = 0; i < shapes.size(); ++i) {
      link.shapes.push_back(readShape(*shapes[i], indexPath(ws, i + 1)));
      if (link.shapes.back().mass > 0) fixedMass += link.shapes.back().mass;
    }
    // Shape masses are shares of the link's mass (physics spreads the rest by volume).
    if (fixedMass > link.mass * (1 + 1e-9))
      fail(ws, "shape masses add up to " + formatNumber(fixedMass) + " kg, more than the link's mass " +
                   formatNumber(link.mass) + " kg");
    if (const Value* c = find(v, "collision")) {
      // Contact geometry only: the mass properties stay those of `shapes`.
      const std::string wc = childPath(where, "collision");
      if (c->type != Value::Type::Table || find(*c, "box") || find(*c, "sphere") || find(*c, "cylinder") ||
          find(*c, "mesh"))
        fail(wc, "expected a list of shapes { { box = {x, y, z} }, ... } (like shapes), got " + describe(*c));
      const auto cs = toList(*c, wc);
      if (cs.empty())
        fail(wc, "expected at least one shape (leave collision out to collide with the shapes)");
      if (cs.size() > kMaxShapesPerLink)
        fail(wc, "a link has at most " + std::to_string(kMaxShapesPerLink) + " collision shapes (got " +
                     std::to_string(cs.size()) + ")");
      std::vector<ShapeDef> collision;
      for (size_t i = 0; i < cs.size(); ++i) {
        const std::string wi = indexPath(wc, i + 1);
        if (cs[i]->type == Value::Type::Table && find(*cs[i], "mass"))
          fail(childPath(wi, "mass"),
               "collision shapes carry no mass (the link's mass properties come from its shapes)");
        collision.push_back(readShape(*cs[i], wi));
      }
      link.collision = massFrom(link.shapes, std::move(collision), link.mass);
    }
    return link;
  }

  ShapeDef readShape(const Value& v, const std::string& where) {
    checkRecord(v, where,
                {"box", "sphere", "cylinder", "mesh", "at", "rot", "quat", "mass", "scale", "axis"});
    ShapeDef s;
    const Value* box = find(v, "box");
    const Value* sphere = find(v, "sphere");
    const Value* cylinder = find(v, "cylinder");
    const Value* mesh = find(v, "mesh");
    const int kinds = (box != nullptr) + (sphere != nullptr) + (cylinder != nullptr) + (mesh != nullptr);
    if (kinds != 1)
      fail(where, std::string("expected exactly one of box, sphere, cylinder, mesh") +
                      (kinds == 0 ? "" : " (this shape has several)"));
    const Value* scale = find(v, "scale");
    const Value* axis = find(v, "axis");
    const Value* rot = find(v, "rot");
    const Value* quat = find(v, "quat");
    if (scale && !mesh) fail(childPath(where, "scale"), "scale is only for mesh shapes");
    if (axis && !cylinder) fail(childPath(where, "axis"), "axis is only for cylinder shapes");
    if (rot && quat) fail(where, "give either rot or quat, not both");
    if (axis && (rot || quat)) fail(childPath(where, "axis"), "give either axis or rot/quat, not both");

    if (box) {
      const std::string w = childPath(where, "box");
      s.kind = ShapeKind::Box;
      s.size = toVec3(*box, w);
      for (int i = 0; i < 3; ++i)
        if (!(s.size[i] > 0 && s.size[i] <= kMaxMagnitude))
          fail(indexPath(w, i + 1), "box sides must be greater than 0 and at most " +
                                        formatNumber(kMaxMagnitude) + " (got " + formatNumber(s.size[i]) +
                                        ")");
    } else if (sphere) {
      s.kind = ShapeKind::Sphere;
      s.radius = toPositive(*sphere, childPath(where, "sphere"));
    } else if (cylinder) {
      const std::string w = childPath(where, "cylinder");
      s.kind = ShapeKind::Cylinder;
      const auto rl = toNumbers(*cylinder, w, 2, 2, "{radius, length} (2 numbers)");
      if (rl[0] <= 0)
        fail(indexPath(w, 1), "radius must be greater than 0 (got " + formatNumber(rl[0]) + ")");
      if (rl[1] <= 0)
        fail(indexPath(w, 2), "length must be greater than 0 (got " + formatNumber(rl[1]) + ")");
      s.radius = rl[0];
      s.length = rl[1];
    } else {
      const std::string w = childPath(where, "mesh");
      const double k = scale ? toPositive(*scale, childPath(where, "scale")) : 1.0;
      loadHull(toName(*mesh, w), k, w, s);
    }

    if (const Value* at = find(v, "at")) s.pose.pos = toVec3(*at, childPath(where, "at"));
    if (rot) {
      const auto rpy =
          toNumbers(*rot, childPath(where, "rot"), 3, 3, "{roll, pitch, yaw} (3 numbers, radians)");
      s.pose.rot = quatFromRpy(rpy[0], rpy[1], rpy[2]);
    } else if (quat) {
      const std::string w = childPath(where, "quat");
      const auto q = toNumbers(*quat, w, 4, 4, "{w, x, y, z} (4 numbers)");
      Quat r(q[0], q[1], q[2], q[3]);
      if (r.norm() < kMinDirection) fail(w, "quaternion must not be zero");
      s.pose.rot = r.normalized();
    } else if (axis) {
      // Cylinders lie along their own z; turn that z onto the named axis.
      const std::string w = childPath(where, "axis");
      const std::string a = toString(*axis, w);
      if (a == "x")
        s.pose.rot = Quat(Eigen::AngleAxisd(kPi / 2, Vec3::UnitY()));
      else if (a == "y")
        s.pose.rot = Quat(Eigen::AngleAxisd(-kPi / 2, Vec3::UnitX()));
      else if (a != "z")
        fail(w, "unknown axis '" + a + "' (expected one of: x, y, z)");
    }
    if (const Value* m = find(v, "mass")) s.mass = toNonNegative(*m, childPath(where, "mass"));
    return s;
  }

  /// Finds the mesh file (the module-type file's folder first, then the project root), loads it
  /// (once per file and scale) and fills the hull fields of s.
  void loadHull(const std::string& name, double scale, const std::string& where, ShapeDef& s) {
    const std::vector<std::string> folders = {m_dir.string(), m_root.string()};
    const ScriptFile f = findScriptFile(name, folders, folders, nullptr);
    if (f.status == ScriptFile::Status::Outside) fail(where, "mesh file " + outsideMessage(name, folders));
    const std::string path = f.path;
    if (path.empty())
      fail(where, "mesh file '" + name + "' not found (looked in " +
                      (m_dir / "").lexically_normal().string() + " and " +
                      (m_root / "").lexically_normal().string() + ", the project root)");
    const std::string display = m_vm.displayName(path);
    auto key = std::make_pair(path, scale);
    auto it = m_meshes.find(key);
    if (it == m_meshes.end()) {
      MeshData mesh;
      std::string err;
      if (!(m_cache ? m_cache->load(path, scale, mesh, err) : loadMesh(path, scale, mesh, err))) {
        if (err.rfind(path, 0) == 0) err = display + err.substr(path.size());
        fail(where, err);
      }
      it = m_meshes.emplace(key, std::move(mesh)).first;
    }
    s.kind = ShapeKind::Hull;
    s.points = it->second.points;
    s.triangles = it->second.triangles;
    s.source = display;
  }

  JointDef readJoint(const ModuleTypeDef& def, const Value& v, const std::string& where) const {
    checkRecord(v, where,
                {"name", "parent", "child", "pivot", "axis", "lower", "upper", "continuous", "torque",
                 "speed", "gain", "stiffness"});
    JointDef j;
    j.name = toName(require(v, where, "name"), childPath(where, "name"));
    j.parent = linkIndex(def, require(v, where, "parent"), childPath(where, "parent"));
    j.child = linkIndex(def, require(v, where, "child"), childPath(where, "child"));
    if (j.parent == j.child) fail(childPath(where, "child"), "a joint needs two different links");
    j.pivot = toVec3(require(v, where, "pivot"), childPath(where, "pivot"));
    j.axis = toDirection(require(v, where, "axis"), childPath(where, "axis"));
    const Value* cont = find(v, "continuous");
    const Value* lower = find(v, "lower");
    const Value* upper = find(v, "upper");
    j.limited = !(cont && toBool(*cont, childPath(where, "continuous")));
    if (!j.limited) {
      if (lower || upper) fail(where, "a continuous joint has no lower/upper limits");
    } else {
      if (!lower || !upper)
        fail(where, std::string("missing required field '") + (lower ? "upper" : "lower") +
                        "' (or set continuous = true)");
      j.lower = toNumber(*lower, childPath(where, "lower"));
      j.upper = toNumber(*upper, childPath(where, "upper"));
      if (j.lower > j.upper)
        fail(where,
             "lower (" + formatNumber(j.lower) + ") is greater than upper (" + formatNumber(j.upper) + ")");
    }
    j.maxTorque = toNonNegative(require(v, where, "torque"), childPath(where, "torque"));
    j.maxSpeed = toNonNegative(require(v, where, "speed"), childPath(where, "speed"));
    if (const Value* g = find(v, "gain")) j.servoGain = toNonNegative(*g, childPath(where, "gain"));
    if (const Value* k = find(v, "stiffness"))
      j.servoStiffness = toNonNegative(*k, childPath(where, "stiffness"));
    return j;
  }

  SensorDef readSensor(const ModuleTypeDef& def, const Value& v, const std::string& where) const {
    checkRecord(v, where, {"type", "name", "link", "at", "dir", "min", "max"});
    SensorDef sd;
    const std::string kind = toString(require(v, where, "type"), childPath(where, "type"));
    static const std::pair<const char*, SensorKind> kinds[] = {{"accelerometer", SensorKind::Accelerometer},
                                                               {"gyro", SensorKind::Gyro},
                                                               {"orientation", SensorKind::Orientation},
                                                               {"position", SensorKind::Position},
                                                               {"range", SensorKind::Range},
                                                               {"contact", SensorKind::Contact}};
    bool known = false;
    for (const auto& [n, k] : kinds)
      if (kind == n) {
        sd.kind = k;
        known = true;
      }
    if (!known)
      fail(childPath(where, "type"),
           "unknown sensor type '" + kind +
               "' (expected one of: accelerometer, gyro, orientation, position, range, contact)");
    sd.link = def.rootLink;
    if (const Value* l = find(v, "link")) sd.link = linkIndex(def, *l, childPath(where, "link"));
    if (sd.kind == SensorKind::Range) {
      sd.name = "range:" + toName(require(v, where, "name"), childPath(where, "name"));
      if (const Value* a = find(v, "at")) sd.pos = toVec3(*a, childPath(where, "at"));
      sd.dir = toDirection(require(v, where, "dir"), childPath(where, "dir"));
      if (const Value* m = find(v, "min")) sd.minRange = toNonNegative(*m, childPath(where, "min"));
      if (const Value* m = find(v, "max")) sd.maxRange = toPositive(*m, childPath(where, "max"));
      if (sd.minRange >= sd.maxRange) fail(where, "min must be less than max");
    } else {
      for (const char* k : {"at", "dir", "min", "max"})
        if (find(v, k)) fail(childPath(where, k), "only range sensors take '" + std::string(k) + "'");
      if (sd.kind == SensorKind::Contact) {
        if (!find(v, "link")) fail(where, "a contact sensor needs 'link'");
        sd.name = "contact:" + def.links[size_t(sd.link)].name;
      } else {
        sd.name = kind;
      }
      if (const Value* n = find(v, "name")) sd.name = toName(*n, childPath(where, "name"));
    }
    return sd;
  }

  DockDef readDock(const ModuleTypeDef& def, const Value& v, const std::string& where) const {
    checkRecord(v, where,
                {"name",           "link",           "at",           "normal",         "up",
                 "gender",         "size",           "symmetry",     "capture_radius", "capture_angle",
                 "latch_distance", "latch_angle",    "capture",      "capture_speed",  "capture_turn_speed",
                 "capture_force",  "capture_torque", "capture_time", "pull",           "strength",
                 "strength_torque"});
    DockDef d;
    d.name = toName(require(v, where, "name"), childPath(where, "name"));
    d.link = linkIndex(def, require(v, where, "link"), childPath(where, "link"));
    d.pos = toVec3(require(v, where, "at"), childPath(where, "at"));
    d.normal = toDirection(require(v, where, "normal"), childPath(where, "normal"));
    if (const Value* up = find(v, "up")) {
      const std::string w = childPath(where, "up");
      d.up = toDirection(*up, w);
      if (std::abs(d.up.dot(d.normal)) > kPerpendicularTol) fail(w, "up must be perpendicular to normal");
    } else {
      // Default reference: z projected into the face, or x when the face looks (nearly) along z.
      const Vec3 ref = std::abs(d.normal.z()) > kNearZ ? Vec3::UnitX() : Vec3::UnitZ();
      d.up = (ref - ref.dot(d.normal) * d.normal).normalized();
    }
    if (const Value* g = find(v, "gender")) {
      const std::string w = childPath(where, "gender");
      const std::string s = toString(*g, w);
      if (s == "none")
        d.gender = Gender::None;
      else if (s == "male")
        d.gender = Gender::Male;
      else if (s == "female")
        d.gender = Gender::Female;
      else
        fail(w, "unknown gender '" + s + "' (expected one of: none, male, female)");
    }
    if (const Value* s = find(v, "size")) d.size = toPositive(*s, childPath(where, "size"));
    if (const Value* s = find(v, "symmetry")) {
      const std::string w = childPath(where, "symmetry");
      const double n = toNumber(*s, w);
      if (!isIntegral(*s) || n < 1 || n > 360)
        fail(w, "expected a whole number from 1 to 360, got " + formatNumber(n));
      d.symmetry = int(n);
    }
    // The numeric keys: those world.docks takes (DockSettings::kFields); pull may be 0.
    for (const DockSettings::Field& f : DockSettings::kFields)
      if (const Value* x = find(v, f.key))
        d.*f.value =
            f.lo > 0 ? toPositive(*x, childPath(where, f.key)) : toNonNegative(*x, childPath(where, f.key));
    if (d.latchDistance > d.captureRadius)
      fail(childPath(where, "latch_distance"), "must not exceed capture_radius");
    if (const Value* c = find(v, "capture")) {
      const std::string w = childPath(where, "capture");
      const std::string s = toString(*c, w);
      if (s == "joint")
        d.capture = DockDef::Capture::Joint;
      else if (s == "magnet")
        d.capture = DockDef::Capture::Magnet;
      else
        fail(w, "unknown capture '" + s + "' (expected one of: joint, magnet)");
    }
    return d;
  }

  /// Every link must hang together with the root through joints, or it would fall away.
  void checkConnected(const ModuleTypeDef& def) const {
    // Joints form a tree over the links: a joint between links already joined (through other
    // joints, or the same link twice) would close a loop the solver cannot hold.
    std::vector<size_t> group(def.links.size());
    for (size_t i = 0; i < group.size(); ++i) group[i] = i;
    auto find = [&group](size_t i) {
      while (group[i] != i) i = group[i] = group[group[i]];
      return i;
    };
    for (size_t k = 0; k < def.joints.size(); ++k) {
      const JointDef& j = def.joints[k];
      const size_t a = find(size_t(j.parent)), b = find(size_t(j.child));
      if (a == b)
        fail(indexPath("joints", k + 1),
             "joint '" + j.name + "' joins links '" + def.links[size_t(j.parent)].name + "' and '" +
                 def.links[size_t(j.child)].name +
                 "', which other joints already join (joints must form a tree from the root link)");
      group[a] = b;
    }
    std::vector<bool> reached(def.links.size(), false);
    reached[size_t(def.rootLink)] = true;
    for (bool grew = true; grew;) {
      grew = false;
      for (const JointDef& j : def.joints) {
        if (reached[size_t(j.parent)] != reached[size_t(j.child)]) {
          reached[size_t(j.parent)] = reached[size_t(j.child)] = true;
          grew = true;
        }
      }
    }
    for (size_t i = 0; i < reached.size(); ++i)
      if (!reached[i])
        fail(indexPath("links", i + 1), "link '" + def.links[i].name +
                                            "' is not connected to the root link '" +
                                            def.links[size_t(def.rootLink)].name + "' by joints");
  }

  const LuaVm& m_vm;
  std::string m_file;
  fs::path m_dir;
  fs::path m_root;
  std::map<std::pair<std::string, double>, MeshData> m_meshes;
  MeshCache* m_cache;
};

}  // namespace

ModuleTypeDef loadModuleType(const std::string& path, const std::string& projectRoot, SourceFiles* sources,
                             MeshCache* meshes) {
  std::error_code ec;
  const fs::path root = fs::absolute(projectRoot, ec).lexically_normal();
  const fs::path file = fs::absolute(path, ec).lexically_normal();
  const fs::path dir = file.parent_path();

  LuaVm vm(kMemoryLimit);
  vm.setInstructionBudget(kInstructionBudget);
  vm.setSources(sources);
  vm.setDisplayRoot(root.string());
  vm.setRequirePath({dir.string(), (root / "assets" / "modules").string(), (root / "lua").string()});
  const std::string display = vm.displayName(file.string());

  std::string err;
  if (!vm.runFile(file.string(), 1, err)) {
    // Syntax and runtime errors already read "file:line: ..."; out-of-memory ones do not.
    if (err.rfind(display + ":", 0) != 0) err = display + ": " + err;
    throw InputError(err);
  }

  const Value top = copyModuleTable(vm.L(), lua_gettop(vm.L()), display);
  lua_settop(vm.L(), 0);
  return TypeReader(vm, display, dir, root, meshes).read(top);
}

}  // namespace rm3d
