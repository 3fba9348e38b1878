// `linalg`: vectors and dense matrices (dynamic size, column-major doubles stored inside the
// userdata, so the VM's allocator counts them against its memory cap and nothing needs a
// finalizer), unit quaternions and rigid transforms, with Eigen doing the arithmetic. This file:
// the `linalg` table, the shared checks and constructors of userdata, and `*`, which mixes the
// types; linalg_matrix.cpp and linalg_rotation.cpp hold the types' own methods.
//
// Work that grows with the cube of a size is charged to the caller's instruction budget
// (LuaVm::charge), so a huge SVD ends like an endless loop rather than stalling the step.
#include "script/linalg_binding.h"

#include <cmath>
#include <cstdint>
#include <cstdio>

#include "script/linalg_internal.h"
#include "script/lua_vm.h"

namespace rm3d {

namespace linalg {

int noMemory(lua_State* L, const char* fn) {
  return luaL_error(L, "linalg: %s: out of memory", fn);
}

void chargeFlops(lua_State* L, double flops) {
  const double n = flops / kFlopsPerInstruction;
  if (n >= 1) LuaVm::charge(L, n > 1e15 ? int64_t(1e15) : int64_t(n), "linear algebra");
}

MatHeader* newMat(lua_State* L, lua_Integer rows, lua_Integer cols, bool vector, const char* fn) {
  if (rows < 1 || cols < 1 || rows > kMaxDim || cols > kMaxDim || rows * cols > kMaxEntries)
    luaL_error(L, "linalg: %s: bad size %dx%d (expected 1 to %d rows and columns, at most %d entries)", fn,
               int(rows), int(cols), int(kMaxDim), int(kMaxEntries));
  const double bytes = double(sizeof(MatHeader)) + double(rows) * double(cols) * sizeof(double);
  char what[96];
  std::snprintf(what, sizeof what, "linalg: %s: a %dx%d matrix", fn, int(rows), int(cols));
  LuaVm::checkRoom(L, bytes, what);
  auto* h = static_cast<MatHeader*>(
      lua_newuserdatauv(L, sizeof(MatHeader) + size_t(rows) * size_t(cols) * sizeof(double), 0));
  h->rows = int32_t(rows);
  h->cols = int32_t(cols);
  h->vector = vector ? 1 : 0;
  h->pad = 0;
  luaL_setmetatable(L, kMatrixMeta);
  return h;
}

void checkFinite(lua_State* L, MatHeader* a, const char* fn) {
  const double* d = a->data();
  for (int64_t k = 0; k < int64_t(a->rows) * a->cols; ++k)
    if (!std::isfinite(d[k]))
      luaL_error(L, "linalg: %s: entry (%d, %d) is %s; expected finite numbers", fn, int(k % a->rows) + 1,
                 int(k / a->rows) + 1,
                 std::isnan(d[k]) ? "nan"
                 : d[k] > 0       ? "inf"
                                  : "-inf");
}

MatHeader* newLike(lua_State* L, const MatHeader* a, const char* fn) {
  return newMat(L, a->rows, a->cols, a->vector != 0, fn);
}

QuatUd* newQuat(lua_State* L, const Quat& q) {
  auto* u = static_cast<QuatUd*>(lua_newuserdatauv(L, sizeof(QuatUd), 0));
  *u = {q.w(), q.x(), q.y(), q.z()};
  luaL_setmetatable(L, kQuatMeta);
  return u;
}

TransformUd* newTransform(lua_State* L, const Quat& q, const Vec3& p) {
  auto* u = static_cast<TransformUd*>(lua_newuserdatauv(L, sizeof(TransformUd), 0));
  *u = {{q.w(), q.x(), q.y(), q.z()}, {p.x(), p.y(), p.z()}};
  luaL_setmetatable(L, kTransformMeta);
  return u;
}

void pushVector3(lua_State* L, const Vec3& v, const char* fn) {
  MatHeader* h = newMat(L, 3, 1, true, fn);
  for (int i = 0; i < 3; ++i) h->data()[i] = v[i];
}

const char* kindName(lua_State* L, int i) {
  if (luaL_testudata(L, i, kMatrixMeta))
    return static_cast<MatHeader*>(lua_touserdata(L, i))->vector ? "vector" : "matrix";
  if (luaL_testudata(L, i, kQuatMeta)) return "quat";
  if (luaL_testudata(L, i, kTransformMeta)) return "transform";
  return luaL_typename(L, i);
}

MatHeader* checkMat(lua_State* L, int i, const char* fn) {
  auto* h = static_cast<MatHeader*>(luaL_testudata(L, i, kMatrixMeta));
  if (!h)
    luaL_error(L, "linalg: %s: argument %d: expected a linalg matrix or vector, got %s", fn, i,
               kindName(L, i));
  return h;
}

QuatUd* checkQuat(lua_State* L, int i, const char* fn) {
  auto* q = static_cast<QuatUd*>(luaL_testudata(L, i, kQuatMeta));
  if (!q) luaL_error(L, "linalg: %s: argument %d: expected a linalg quat, got %s", fn, i, kindName(L, i));
  return q;
}

TransformUd* checkTransform(lua_State* L, int i, const char* fn) {
  auto* t = static_cast<TransformUd*>(luaL_testudata(L, i, kTransformMeta));
  if (!t)
    luaL_error(L, "linalg: %s: argument %d: expected a linalg transform, got %s", fn, i, kindName(L, i));
  return t;
}

double checkEntry(lua_State* L, int idx, const char* fn, const char* what, int i, int j) {
  if (lua_type(L, idx) != LUA_TNUMBER) {
    if (j > 0)
      luaL_error(L, "linalg: %s: %s (%d, %d): expected a number, got %s", fn, what, i, j,
                 luaL_typename(L, idx));
    luaL_error(L, "linalg: %s: %s %d: expected a number, got %s", fn, what, i, luaL_typename(L, idx));
  }
  return lua_tonumber(L, idx);
}

/// A 3-vector argument: a linalg vector (or any 3 x 1 matrix) or a table {x, y, z}.
Vec3 check3(lua_State* L, int i, const char* fn) {
  if (auto* h = static_cast<MatHeader*>(luaL_testudata(L, i, kMatrixMeta))) {
    if (h->rows * h->cols != 3 || (h->rows != 3 && h->cols != 3))
      luaL_error(L, "linalg: %s: argument %d: expected a 3-vector, got a %dx%d %s", fn, i, h->rows, h->cols,
                 h->vector ? "vector" : "matrix");
    return Vec3(h->data()[0], h->data()[1], h->data()[2]);
  }
  if (lua_type(L, i) != LUA_TTABLE)
    luaL_error(L, "linalg: %s: argument %d: expected a 3-vector (a linalg vector or {x, y, z}), got %s", fn,
               i, kindName(L, i));
  if (lua_rawlen(L, i) != 3)
    luaL_error(L, "linalg: %s: argument %d: expected {x, y, z}, got a table of %d entries", fn, i,
               int(lua_rawlen(L, i)));
  Vec3 v;
  for (int k = 0; k < 3; ++k) {
    lua_rawgeti(L, i, k + 1);
    v[k] = checkEntry(L, -1, fn, "entry", k + 1, 0);
    lua_pop(L, 1);
  }
  return v;
}

int shapeMismatch(lua_State* L, const char* op, const MatHeader* a, const MatHeader* b) {
  return luaL_error(L, "linalg: shape mismatch: %dx%d %s %dx%d", a->rows, a->cols, op, b->rows, b->cols);
}

int needSquare(lua_State* L, const char* fn, const MatHeader* a) {
  return luaL_error(L, "linalg: %s: expected a square matrix, got %dx%d", fn, a->rows, a->cols);
}

/// Every `*`: scalar * matrix, matrix * matrix (or vector), quat * quat, quat * vector (rotates),
/// transform * transform, transform * vector (a point).
int anyMul(lua_State* L) {
  auto* ma = static_cast<MatHeader*>(luaL_testudata(L, 1, kMatrixMeta));
  auto* mb = static_cast<MatHeader*>(luaL_testudata(L, 2, kMatrixMeta));
  if (ma && lua_type(L, 2) == LUA_TNUMBER) return matScaled(L, ma, lua_tonumber(L, 2));
  if (mb && lua_type(L, 1) == LUA_TNUMBER) return matScaled(L, mb, lua_tonumber(L, 1));
  if (ma && mb) {
    if (ma->cols != mb->rows) return shapeMismatch(L, "*", ma, mb);
    chargeFlops(L, double(ma->rows) * ma->cols * mb->cols);
    MatHeader* r = newMat(L, ma->rows, mb->cols, mb->vector != 0, "*");
    const int st = guarded([&] {
      map(r).noalias() = map(ma) * map(mb);
      return kOk;
    });
    if (st == kNoMemory) return noMemory(L, "*");
    return 1;
  }
  if (auto* qa = static_cast<QuatUd*>(luaL_testudata(L, 1, kQuatMeta))) {
    if (auto* qb = static_cast<QuatUd*>(luaL_testudata(L, 2, kQuatMeta))) {
      newQuat(L, (toQuat(qa) * toQuat(qb)).normalized());
      return 1;
    }
    if (mb) {
      pushVector3(L, toQuat(qa) * check3(L, 2, "*"), "*");
      return 1;
    }
  }
  if (auto* ta = static_cast<TransformUd*>(luaL_testudata(L, 1, kTransformMeta))) {
    const Quat qa = toQuat(ta);
    const Vec3 pa(ta->p[0], ta->p[1], ta->p[2]);
    if (auto* tb = static_cast<TransformUd*>(luaL_testudata(L, 2, kTransformMeta))) {
      newTransform(L, (qa * toQuat(tb)).normalized(), pa + qa * Vec3(tb->p[0], tb->p[1], tb->p[2]));
      return 1;
    }
    if (mb) {
      pushVector3(L, pa + qa * check3(L, 2, "*"), "*");
      return 1;
    }
  }
  return luaL_error(L, "linalg: cannot multiply %s by %s", kindName(L, 1), kindName(L, 2));
}

void newMeta(lua_State* L, const char* name, const luaL_Reg* metamethods, const luaL_Reg* methods) {
  luaL_newmetatable(L, name);
  luaL_setfuncs(L, metamethods, 0);
  lua_newtable(L);
  luaL_setfuncs(L, methods, 0);
  lua_setfield(L, -2, "__index");
  lua_pushstring(L, name);
  lua_setfield(L, -2, "__name");
  sealMetatable(L);  // scripts cannot swap or read the metatable
  lua_pop(L, 1);
}

}  // namespace linalg

int openLinalg(lua_State* L) {
  using namespace linalg;
  openMatrixType(L);
  openRotationTypes(L);
  static const luaL_Reg fns[] = {{"matrix", linalgMatrix},       {"vector", linalgVector},
                                 {"identity", linalgIdentity},   {"zeros", linalgZeros},
                                 {"quat", linalgQuat},           {"quat_axis_angle", linalgQuatAxisAngle},
                                 {"transform", linalgTransform}, {nullptr, nullptr}};
  luaL_newlib(L, fns);
  return 1;
}

}  // namespace rm3d
