// linalg unit quaternions ("linalg.quat") and rigid transforms ("linalg.transform"):
// constructors and methods; their `*` is in linalg_binding.cpp.
#include <cmath>

#include "script/linalg_internal.h"

namespace rm3d::linalg {

namespace {

// ---- quaternions ----

/// q:rotate(v) -> vector
int quatRotate(lua_State* L) {
  const Quat q = toQuat(checkQuat(L, 1, "rotate"));
  pushVector3(L, q * check3(L, 2, "rotate"), "rotate");
  return 1;
}

/// q:inv() (the conjugate of a unit quaternion)
int quatInv(lua_State* L) {
  newQuat(L, toQuat(checkQuat(L, 1, "inv")).conjugate());
  return 1;
}

/// q:matrix() -> 3x3 rotation
int quatMatrix(lua_State* L) {
  const Quat q = toQuat(checkQuat(L, 1, "matrix"));
  MatHeader* r = newMat(L, 3, 3, false, "matrix");
  map(r) = q.toRotationMatrix();
  return 1;
}

/// q:totable() -> {w, x, y, z}
int quatToTable(lua_State* L) {
  QuatUd* q = checkQuat(L, 1, "totable");
  lua_createtable(L, 4, 0);
  const double c[4] = {q->w, q->x, q->y, q->z};
  for (int k = 0; k < 4; ++k) {
    lua_pushnumber(L, c[k]);
    lua_rawseti(L, -2, k + 1);
  }
  return 1;
}

/// q:angle() -> rotation angle in [0, pi]
int quatAngle(lua_State* L) {
  lua_pushnumber(L, Eigen::AngleAxisd(toQuat(checkQuat(L, 1, "angle"))).angle());
  return 1;
}

int quatEq(lua_State* L) {
  auto* a = static_cast<QuatUd*>(luaL_testudata(L, 1, kQuatMeta));
  auto* b = static_cast<QuatUd*>(luaL_testudata(L, 2, kQuatMeta));
  lua_pushboolean(L, a && b && a->w == b->w && a->x == b->x && a->y == b->y && a->z == b->z);
  return 1;
}

int quatToString(lua_State* L) {
  QuatUd* q = checkQuat(L, 1, "tostring");
  char s[160];
  std::snprintf(s, sizeof s, "quat{%.6g, %.6g, %.6g, %.6g}", q->w, q->x, q->y, q->z);
  lua_pushstring(L, s);
  return 1;
}

// ---- rigid transforms ----

/// T:inv()
int transformInv(lua_State* L) {
  TransformUd* t = checkTransform(L, 1, "inv");
  const Quat qi = toQuat(t).conjugate();
  newTransform(L, qi, -(qi * Vec3(t->p[0], t->p[1], t->p[2])));
  return 1;
}

/// T:rotation() -> quat
int transformRotation(lua_State* L) {
  newQuat(L, toQuat(checkTransform(L, 1, "rotation")));
  return 1;
}

/// T:translation() -> vector
int transformTranslation(lua_State* L) {
  TransformUd* t = checkTransform(L, 1, "translation");
  pushVector3(L, Vec3(t->p[0], t->p[1], t->p[2]), "translation");
  return 1;
}

/// T:matrix() -> 4x4 homogeneous
int transformMatrix(lua_State* L) {
  TransformUd* t = checkTransform(L, 1, "matrix");
  MatHeader* r = newMat(L, 4, 4, false, "matrix");
  auto m = map(r);
  m.setIdentity();
  m.topLeftCorner(3, 3) = toQuat(t).toRotationMatrix();
  m.topRightCorner(3, 1) = Vec3(t->p[0], t->p[1], t->p[2]);
  return 1;
}

int transformEq(lua_State* L) {
  auto* a = static_cast<TransformUd*>(luaL_testudata(L, 1, kTransformMeta));
  auto* b = static_cast<TransformUd*>(luaL_testudata(L, 2, kTransformMeta));
  bool same = a && b;
  for (int k = 0; same && k < 4; ++k) same = a->q[k] == b->q[k];
  for (int k = 0; same && k < 3; ++k) same = a->p[k] == b->p[k];
  lua_pushboolean(L, same);
  return 1;
}

int transformToString(lua_State* L) {
  TransformUd* t = checkTransform(L, 1, "tostring");
  char s[256];
  std::snprintf(s, sizeof s, "transform{quat{%.6g, %.6g, %.6g, %.6g}, {%.6g, %.6g, %.6g}}", t->q[0], t->q[1],
                t->q[2], t->q[3], t->p[0], t->p[1], t->p[2]);
  lua_pushstring(L, s);
  return 1;
}

}  // namespace

namespace {

Quat checkedUnit(lua_State* L, const Quat& q, const char* fn) {
  const double n = q.norm();
  if (!std::isfinite(n) || n < 1e-12)
    luaL_error(L, "linalg: %s: expected a non-zero finite quaternion, got (%f, %f, %f, %f)", fn, q.w(), q.x(),
               q.y(), q.z());
  return Quat(q.coeffs() / n);
}

}  // namespace

/// linalg.quat(w, x, y, z) or linalg.quat{w, x, y, z}; normalised
int linalgQuat(lua_State* L) {
  double c[4];
  if (lua_type(L, 1) == LUA_TTABLE) {
    if (lua_rawlen(L, 1) != 4)
      return luaL_error(L, "linalg: quat: expected {w, x, y, z}, got a table of %d entries",
                        int(lua_rawlen(L, 1)));
    for (int k = 0; k < 4; ++k) {
      lua_rawgeti(L, 1, k + 1);
      c[k] = checkEntry(L, -1, "quat", "entry", k + 1, 0);
      lua_pop(L, 1);
    }
  } else {
    for (int k = 0; k < 4; ++k) {
      if (lua_type(L, k + 1) != LUA_TNUMBER)
        return luaL_error(L, "linalg: quat: expected quat(w, x, y, z) or quat{w, x, y, z}, argument %d is %s",
                          k + 1, kindName(L, k + 1));
      c[k] = lua_tonumber(L, k + 1);
    }
  }
  newQuat(L, checkedUnit(L, Quat(c[0], c[1], c[2], c[3]), "quat"));
  return 1;
}

/// linalg.quat_axis_angle(axis, angle)
int linalgQuatAxisAngle(lua_State* L) {
  const Vec3 axis = check3(L, 1, "quat_axis_angle");
  const double angle = luaL_checknumber(L, 2);
  const double n = axis.norm();
  if (!(n > 1e-12) || !std::isfinite(n) || !std::isfinite(angle))
    return luaL_error(L, "linalg: quat_axis_angle: expected a non-zero finite axis and a finite angle");
  newQuat(L, Quat(Eigen::AngleAxisd(angle, axis / n)));
  return 1;
}

namespace {

/// Rotation argument: a quat or a 3x3 rotation matrix.
Quat checkRotation(lua_State* L, int i, const char* fn) {
  if (auto* q = static_cast<QuatUd*>(luaL_testudata(L, i, kQuatMeta))) return toQuat(q);
  auto* h = static_cast<MatHeader*>(luaL_testudata(L, i, kMatrixMeta));
  if (!h || h->rows != 3 || h->cols != 3)
    luaL_error(L, "linalg: %s: argument %d: expected a quat or a 3x3 rotation matrix, got %s", fn, i,
               kindName(L, i));
  const Eigen::Matrix3d r = Eigen::Map<Eigen::Matrix3d>(h->data());
  const double err = (r.transpose() * r - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
  if (!(err < 1e-6) || !(r.determinant() > 0))
    luaL_error(L, "linalg: %s: argument %d: the matrix is not a rotation (orthonormal, determinant 1)", fn,
               i);
  return Quat(r).normalized();
}

}  // namespace

/// linalg.transform([R], [p]): R a quat or 3x3 rotation (default identity), p a 3-vector
int linalgTransform(lua_State* L) {
  const Quat q = lua_isnoneornil(L, 1) ? Quat::Identity() : checkRotation(L, 1, "transform");
  const Vec3 p = lua_isnoneornil(L, 2) ? Vec3::Zero() : check3(L, 2, "transform");
  newTransform(L, q, p);
  return 1;
}

void openRotationTypes(lua_State* L) {
  static const luaL_Reg quatMeta[] = {
      {"__mul", &anyMul}, {"__eq", &quatEq}, {"__tostring", &quatToString}, {nullptr, nullptr}};
  static const luaL_Reg quatMethods[] = {{"rotate", quatRotate},   {"inv", quatInv},
                                         {"matrix", quatMatrix},   {"angle", quatAngle},
                                         {"totable", quatToTable}, {nullptr, nullptr}};
  static const luaL_Reg transformMeta[] = {
      {"__mul", &anyMul}, {"__eq", &transformEq}, {"__tostring", &transformToString}, {nullptr, nullptr}};
  static const luaL_Reg transformMethods[] = {{"inv", transformInv},
                                              {"rotation", transformRotation},
                                              {"translation", transformTranslation},
                                              {"matrix", transformMatrix},
                                              {nullptr, nullptr}};
  newMeta(L, kQuatMeta, quatMeta, quatMethods);
  newMeta(L, kTransformMeta, transformMeta, transformMethods);
}

}  // namespace rm3d::linalg
