// `linalg`: vectors and dense matrices (dynamic size, column-major doubles stored inside the
// userdata, so the VM's allocator counts them against its memory cap and nothing needs a
// finalizer), unit quaternions and rigid transforms, with Eigen doing the arithmetic.
//
// Lua errors longjmp: every Eigen object with a destructor lives in an inner scope (`guarded`)
// that returns a status, and the error is raised after that scope is gone. Work that grows
// with the cube of a size is charged to the caller's instruction budget (LuaVm::charge), so a
// huge SVD ends like an endless loop rather than stalling the step.
#include "script/linalg_binding.h"

#include <Eigen/Cholesky>
#include <Eigen/Dense>
#include <Eigen/SVD>
#include <cmath>
#include <cstdint>
#include <lua.hpp>
#include <new>

#include "script/lua_vm.h"

namespace rm3d {

namespace {

constexpr const char* kMatrixMeta = "linalg.matrix";
constexpr const char* kQuatMeta = "linalg.quat";
constexpr const char* kTransformMeta = "linalg.transform";
constexpr lua_Integer kMaxDim = 1 << 16;      ///< rows or columns
constexpr lua_Integer kMaxEntries = 1 << 24;  ///< rows * columns (128 MiB of doubles)
constexpr int kMaxShownEntries = 64;          ///< __tostring prints larger ones by shape only
constexpr int kFlopsPerInstruction = 16;      ///< budget charge for cubic work
constexpr int kSmall = 16;                    ///< DLS systems up to this size stay on the stack

/// The userdata header; the entries (column-major doubles) follow it. 16 bytes, so the entries
/// keep the 8-byte alignment Lua gives userdata (Eigen maps them unaligned).
struct MatHeader {
  int32_t rows = 0, cols = 0;
  int32_t vector = 0;  ///< 1: made as a vector (n x 1): get(i), #v, products stay vectors
  int32_t pad = 0;
  double* data() { return reinterpret_cast<double*>(this + 1); }
};
static_assert(sizeof(MatHeader) == 16);

struct QuatUd {
  double w, x, y, z;
};

struct TransformUd {
  double q[4];  ///< rotation, w x y z
  double p[3];  ///< translation
};

using MapM = Eigen::Map<Eigen::MatrixXd>;
using Quat = Eigen::Quaterniond;
using Vec3 = Eigen::Vector3d;

MapM map(MatHeader* h) {
  return MapM(h->data(), h->rows, h->cols);
}
Quat toQuat(const QuatUd* q) {
  return Quat(q->w, q->x, q->y, q->z);
}
Quat toQuat(const TransformUd* t) {
  return Quat(t->q[0], t->q[1], t->q[2], t->q[3]);
}

enum Status { kOk = 0, kFailed = 1, kNoMemory = 2 };

/// Runs f (which returns a Status) with every C++ temporary inside; a failed allocation is a status.
template <class F>
int guarded(F&& f) {
  try {
    return f();
  } catch (const std::bad_alloc&) {
    return kNoMemory;
  }
}

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
  auto* h = static_cast<MatHeader*>(
      lua_newuserdatauv(L, sizeof(MatHeader) + size_t(rows) * size_t(cols) * sizeof(double), 0));
  h->rows = int32_t(rows);
  h->cols = int32_t(cols);
  h->vector = vector ? 1 : 0;
  h->pad = 0;
  luaL_setmetatable(L, kMatrixMeta);
  return h;
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

// ---- constructors ----

/// linalg.matrix{{a, b}, {c, d}} (rows)
int linalgMatrix(lua_State* L) {
  const char* fn = "matrix";
  if (lua_type(L, 1) != LUA_TTABLE)
    return luaL_error(L, "linalg: matrix: expected a table of rows ({{1, 2}, {3, 4}}), got %s",
                      kindName(L, 1));
  const lua_Integer rows = lua_Integer(lua_rawlen(L, 1));
  if (rows < 1) return luaL_error(L, "linalg: matrix: expected at least one row, got an empty table");
  lua_rawgeti(L, 1, 1);
  if (lua_type(L, -1) != LUA_TTABLE)
    return luaL_error(L, "linalg: matrix: row 1: expected a table of numbers, got %s", luaL_typename(L, -1));
  const lua_Integer cols = lua_Integer(lua_rawlen(L, -1));
  lua_pop(L, 1);
  if (cols < 1) return luaL_error(L, "linalg: matrix: row 1 is empty");
  MatHeader* h = newMat(L, rows, cols, false, fn);
  const int out = lua_gettop(L);
  double* d = h->data();
  for (lua_Integer i = 1; i <= rows; ++i) {
    lua_rawgeti(L, 1, i);
    if (lua_type(L, -1) != LUA_TTABLE)
      return luaL_error(L, "linalg: matrix: row %d: expected a table of numbers, got %s", int(i),
                        luaL_typename(L, -1));
    if (lua_Integer(lua_rawlen(L, -1)) != cols)
      return luaL_error(L, "linalg: matrix: row %d has %d entries, row 1 has %d", int(i),
                        int(lua_rawlen(L, -1)), int(cols));
    for (lua_Integer j = 1; j <= cols; ++j) {
      lua_rawgeti(L, -1, j);
      d[(j - 1) * rows + (i - 1)] = checkEntry(L, -1, fn, "entry", int(i), int(j));
      lua_pop(L, 1);
    }
    lua_pop(L, 1);
  }
  lua_settop(L, out);
  return 1;
}

/// linalg.vector{x, y, ...} or linalg.vector(n) (zeros)
int linalgVector(lua_State* L) {
  if (lua_type(L, 1) == LUA_TNUMBER) {
    MatHeader* h = newMat(L, luaL_checkinteger(L, 1), 1, true, "vector");
    map(h).setZero();
    return 1;
  }
  if (lua_type(L, 1) != LUA_TTABLE)
    return luaL_error(L, "linalg: vector: expected a table of numbers ({1, 2, 3}) or a size, got %s",
                      kindName(L, 1));
  const lua_Integer n = lua_Integer(lua_rawlen(L, 1));
  if (n < 1) return luaL_error(L, "linalg: vector: expected at least one entry, got an empty table");
  MatHeader* h = newMat(L, n, 1, true, "vector");
  for (lua_Integer i = 1; i <= n; ++i) {
    lua_rawgeti(L, 1, i);
    h->data()[i - 1] = checkEntry(L, -1, "vector", "entry", int(i), 0);
    lua_pop(L, 1);
  }
  return 1;
}

/// linalg.identity(n)
int linalgIdentity(lua_State* L) {
  const lua_Integer n = luaL_checkinteger(L, 1);
  MatHeader* h = newMat(L, n, n, false, "identity");
  map(h).setIdentity();
  return 1;
}

/// linalg.zeros(r, c) -> matrix; linalg.zeros(n) -> vector
int linalgZeros(lua_State* L) {
  const lua_Integer r = luaL_checkinteger(L, 1);
  MatHeader* h = lua_isnoneornil(L, 2) ? newMat(L, r, 1, true, "zeros")
                                       : newMat(L, r, luaL_checkinteger(L, 2), false, "zeros");
  map(h).setZero();
  return 1;
}

Quat checkedUnit(lua_State* L, const Quat& q, const char* fn) {
  const double n = q.norm();
  if (!std::isfinite(n) || n < 1e-12)
    luaL_error(L, "linalg: %s: expected a non-zero finite quaternion, got (%f, %f, %f, %f)", fn, q.w(), q.x(),
               q.y(), q.z());
  return Quat(q.coeffs() / n);
}

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

/// linalg.transform([R], [p]): R a quat or 3x3 rotation (default identity), p a 3-vector
int linalgTransform(lua_State* L) {
  const Quat q = lua_isnoneornil(L, 1) ? Quat::Identity() : checkRotation(L, 1, "transform");
  const Vec3 p = lua_isnoneornil(L, 2) ? Vec3::Zero() : check3(L, 2, "transform");
  newTransform(L, q, p);
  return 1;
}

// ---- matrix methods ----

int matRows(lua_State* L) {
  lua_pushinteger(L, checkMat(L, 1, "rows")->rows);
  return 1;
}

int matCols(lua_State* L) {
  lua_pushinteger(L, checkMat(L, 1, "cols")->cols);
  return 1;
}

/// Reads (i, j) or, for a vector or a column, (i), from argument 2 on; `values` is how many
/// arguments follow the indices (set: 1). Returns the flat index; `nextArg` is the argument after.
lua_Integer checkIndex(lua_State* L, MatHeader* h, const char* fn, int values, int& nextArg) {
  const int indices = lua_gettop(L) - 1 - values;
  const lua_Integer i = luaL_checkinteger(L, 2);
  lua_Integer j = 1;
  nextArg = 3;
  if (indices >= 2) {
    j = luaL_checkinteger(L, 3);
    nextArg = 4;
  } else if (h->cols != 1) {
    luaL_error(L, "linalg: %s: a %dx%d matrix needs a row and a column index", fn, h->rows, h->cols);
  }
  if (i < 1 || i > h->rows || j < 1 || j > h->cols) {
    if (h->vector && indices < 2)
      luaL_error(L, "linalg: %s: index %d out of range (the vector has %d entries)", fn, int(i),
                 int(h->rows));
    luaL_error(L, "linalg: %s: index (%d, %d) out of range for a %dx%d matrix", fn, int(i), int(j), h->rows,
               h->cols);
  }
  return (j - 1) * h->rows + (i - 1);
}

/// A:get(i, j), v:get(i)
int matGet(lua_State* L) {
  MatHeader* h = checkMat(L, 1, "get");
  int next = 0;
  lua_pushnumber(L, h->data()[checkIndex(L, h, "get", 0, next)]);
  return 1;
}

/// A:set(i, j, x), v:set(i, x); returns A
int matSet(lua_State* L) {
  MatHeader* h = checkMat(L, 1, "set");
  int next = 0;
  if (lua_gettop(L) < 3)
    return luaL_error(L, "linalg: set: expected set(i, j, value) or, for a vector, set(i, value)");
  const lua_Integer k = checkIndex(L, h, "set", 1, next);
  if (lua_type(L, next) != LUA_TNUMBER)
    return luaL_error(L, "linalg: set: the value (argument %d) must be a number, got %s", next,
                      kindName(L, next));
  h->data()[k] = lua_tonumber(L, next);
  lua_settop(L, 1);
  return 1;
}

/// #v (entries of a vector; rows of a matrix)
int matLen(lua_State* L) {
  lua_pushinteger(L, checkMat(L, 1, "#")->rows);
  return 1;
}

/// A:t() transpose (a vector's is a 1 x n matrix)
int matT(lua_State* L) {
  MatHeader* a = checkMat(L, 1, "t");
  MatHeader* r = newMat(L, a->cols, a->rows, false, "t");
  map(r) = map(a).transpose();
  return 1;
}

int matCopy(lua_State* L) {
  MatHeader* a = checkMat(L, 1, "copy");
  MatHeader* r = newLike(L, a, "copy");
  map(r) = map(a);
  return 1;
}

/// A:inv() (square; errors when singular)
int matInv(lua_State* L) {
  MatHeader* a = checkMat(L, 1, "inv");
  if (a->rows != a->cols) return needSquare(L, "inv", a);
  chargeFlops(L, double(a->rows) * a->rows * a->rows);
  MatHeader* r = newMat(L, a->rows, a->rows, false, "inv");
  int rank = 0;
  const int st = guarded([&] {
    Eigen::FullPivLU<Eigen::MatrixXd> lu(map(a));
    rank = int(lu.rank());
    if (!lu.isInvertible()) return kFailed;
    map(r) = lu.inverse();
    return kOk;
  });
  if (st == kNoMemory) return noMemory(L, "inv");
  if (st == kFailed)
    return luaL_error(L, "linalg: inv: singular matrix (%dx%d, rank %d)", a->rows, a->cols, rank);
  return 1;
}

/// A:det()
int matDet(lua_State* L) {
  MatHeader* a = checkMat(L, 1, "det");
  if (a->rows != a->cols) return needSquare(L, "det", a);
  chargeFlops(L, double(a->rows) * a->rows * a->rows);
  double det = 0;
  const int st = guarded([&] {
    det = map(a).determinant();
    return kOk;
  });
  if (st == kNoMemory) return noMemory(L, "det");
  lua_pushnumber(L, det);
  return 1;
}

/// A:solve(b): x with A x = b (square A; least squares otherwise)
int matSolve(lua_State* L) {
  MatHeader* a = checkMat(L, 1, "solve");
  MatHeader* b = checkMat(L, 2, "solve");
  if (a->rows != b->rows) {
    return luaL_error(
        L, "linalg: shape mismatch: solve of %dx%d with a right-hand side of %dx%d (expected %d rows)",
        a->rows, a->cols, b->rows, b->cols, a->rows);
  }
  chargeFlops(L,
              double(a->rows) * a->cols * std::min(a->rows, a->cols) + double(a->rows) * a->cols * b->cols);
  MatHeader* x = newMat(L, a->cols, b->cols, b->vector != 0, "solve");
  int rank = 0;
  const int st = guarded([&] {
    if (a->rows == a->cols) {
      Eigen::FullPivLU<Eigen::MatrixXd> lu(map(a));
      rank = int(lu.rank());
      if (!lu.isInvertible()) return kFailed;
      map(x) = lu.solve(map(b));
    } else {
      map(x) = map(a).completeOrthogonalDecomposition().solve(map(b));
    }
    return kOk;
  });
  if (st == kNoMemory) return noMemory(L, "solve");
  if (st == kFailed)
    return luaL_error(
        L,
        "linalg: solve: singular matrix (%dx%d, rank %d); A:pinv() * b or A:dls(b, lambda) give a "
        "least-squares answer",
        a->rows, a->cols, rank);
  return 1;
}

/// A:pinv([tol]): Moore-Penrose pseudo-inverse; singular values below tol (default
/// eps * max(r, c) * largest) count as zero
int matPinv(lua_State* L) {
  MatHeader* a = checkMat(L, 1, "pinv");
  const double tol = luaL_optnumber(L, 2, -1);
  chargeFlops(L, 4.0 * a->rows * a->cols * std::min(a->rows, a->cols));
  MatHeader* r = newMat(L, a->cols, a->rows, false, "pinv");
  const int st = guarded([&] {
    Eigen::JacobiSVD<Eigen::MatrixXd> svd(map(a), Eigen::ComputeThinU | Eigen::ComputeThinV);
    const Eigen::VectorXd& s = svd.singularValues();
    const double cut = tol >= 0 ? tol
                                : std::numeric_limits<double>::epsilon() * std::max(a->rows, a->cols) *
                                      (s.size() ? s[0] : 0.0);
    Eigen::VectorXd inv = s;
    for (Eigen::Index k = 0; k < s.size(); ++k) inv[k] = s[k] > cut ? 1.0 / s[k] : 0.0;
    map(r) = svd.matrixV() * inv.asDiagonal() * svd.matrixU().transpose();
    return kOk;
  });
  if (st == kNoMemory) return noMemory(L, "pinv");
  return 1;
}

/// A:svd() -> U, s, V with A = U diag(s) V^T (thin: k = min(r, c) columns; s descending)
int matSvd(lua_State* L) {
  MatHeader* a = checkMat(L, 1, "svd");
  chargeFlops(L, 4.0 * a->rows * a->cols * std::min(a->rows, a->cols));
  const int k = std::min(a->rows, a->cols);
  MatHeader* u = newMat(L, a->rows, k, false, "svd");
  MatHeader* s = newMat(L, k, 1, true, "svd");
  MatHeader* v = newMat(L, a->cols, k, false, "svd");
  const int st = guarded([&] {
    Eigen::JacobiSVD<Eigen::MatrixXd> svd(map(a), Eigen::ComputeThinU | Eigen::ComputeThinV);
    map(u) = svd.matrixU();
    map(s) = svd.singularValues();
    map(v) = svd.matrixV();
    return kOk;
  });
  if (st == kNoMemory) return noMemory(L, "svd");
  return 3;
}

/// x = (A^T A + l^2 I)^-1 A^T b, through the smaller of the two normal systems (for rows < cols,
/// A^T (A A^T + l^2 I)^-1 b, the same x). M is a matrix type (fixed-capacity for small sizes).
template <class M>
int dlsSolve(MatHeader* a, MatHeader* b, double lambda, MatHeader* x) {
  const auto A = map(a);
  const double l2 = lambda * lambda;
  if (a->rows <= a->cols) {
    M n = A * A.transpose();
    n.diagonal().array() += l2;
    Eigen::LDLT<M> ldlt(n);
    if (ldlt.info() != Eigen::Success) return kFailed;
    M y = ldlt.solve(map(b));
    map(x).noalias() = A.transpose() * y;
  } else {
    M n = A.transpose() * A;
    n.diagonal().array() += l2;
    Eigen::LDLT<M> ldlt(n);
    if (ldlt.info() != Eigen::Success) return kFailed;
    M atb = A.transpose() * map(b);
    map(x) = ldlt.solve(atb);
  }
  return map(x).allFinite() ? kOk : kFailed;
}

/// A:dls(b, lambda): damped least squares
int matDls(lua_State* L) {
  MatHeader* a = checkMat(L, 1, "dls");
  MatHeader* b = checkMat(L, 2, "dls");
  if (lua_type(L, 3) != LUA_TNUMBER)
    return luaL_error(L, "linalg: dls: the damping lambda (argument 2) must be a number, got %s",
                      kindName(L, 3));
  const double lambda = lua_tonumber(L, 3);
  if (!(lambda >= 0) || !std::isfinite(lambda))
    return luaL_error(L, "linalg: dls: the damping lambda must be finite and >= 0, got %f", lambda);
  if (a->rows != b->rows)
    return luaL_error(
        L, "linalg: shape mismatch: dls of %dx%d with a right-hand side of %dx%d (expected %d rows)", a->rows,
        a->cols, b->rows, b->cols, a->rows);
  const int small = std::min(a->rows, a->cols);
  chargeFlops(L, double(a->rows) * a->cols * small + double(small) * small * small);
  MatHeader* x = newMat(L, a->cols, b->cols, b->vector != 0, "dls");
  const int st = guarded([&] {
    if (small <= kSmall && b->cols <= kSmall)
      return dlsSolve<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kSmall, kSmall>>(a, b, lambda,
                                                                                                x);
    return dlsSolve<Eigen::MatrixXd>(a, b, lambda, x);
  });
  if (st == kNoMemory) return noMemory(L, "dls");
  if (st == kFailed)
    return luaL_error(L, "linalg: dls: singular system (%dx%d, lambda %f); use lambda > 0", a->rows, a->cols,
                      lambda);
  return 1;
}

/// A:norm() (Euclidean; Frobenius for matrices)
int matNorm(lua_State* L) {
  lua_pushnumber(L, map(checkMat(L, 1, "norm")).norm());
  return 1;
}

/// v:normalized()
int matNormalized(lua_State* L) {
  MatHeader* a = checkMat(L, 1, "normalized");
  const double n = map(a).norm();
  if (!(n > 0) || !std::isfinite(n)) return luaL_error(L, "linalg: normalized: the norm is %f", n);
  MatHeader* r = newLike(L, a, "normalized");
  map(r) = map(a) / n;
  return 1;
}

/// v:dot(w)
int matDot(lua_State* L) {
  MatHeader* a = checkMat(L, 1, "dot");
  MatHeader* b = checkMat(L, 2, "dot");
  if (a->rows * a->cols != b->rows * b->cols || (a->cols != 1 && a->rows != 1) ||
      (b->cols != 1 && b->rows != 1))
    return shapeMismatch(L, "dot", a, b);
  double s = 0;
  for (int k = 0; k < a->rows * a->cols; ++k) s += a->data()[k] * b->data()[k];
  lua_pushnumber(L, s);
  return 1;
}

/// v:cross(w) (3-vectors)
int matCross(lua_State* L) {
  const Vec3 a = check3(L, 1, "cross"), b = check3(L, 2, "cross");
  pushVector3(L, a.cross(b), "cross");
  return 1;
}

/// A:totable() -> {{...}, ...} (rows), v:totable() -> {...}
int matToTable(lua_State* L) {
  MatHeader* a = checkMat(L, 1, "totable");
  if (a->vector) {
    lua_createtable(L, a->rows, 0);
    for (int i = 0; i < a->rows; ++i) {
      lua_pushnumber(L, a->data()[i]);
      lua_rawseti(L, -2, i + 1);
    }
    return 1;
  }
  lua_createtable(L, a->rows, 0);
  for (int i = 0; i < a->rows; ++i) {
    lua_createtable(L, a->cols, 0);
    for (int j = 0; j < a->cols; ++j) {
      lua_pushnumber(L, a->data()[j * a->rows + i]);
      lua_rawseti(L, -2, j + 1);
    }
    lua_rawseti(L, -2, i + 1);
  }
  return 1;
}

// ---- operators ----

int matAddSub(lua_State* L, bool add) {
  const char* op = add ? "+" : "-";
  MatHeader* a = static_cast<MatHeader*>(luaL_testudata(L, 1, kMatrixMeta));
  MatHeader* b = static_cast<MatHeader*>(luaL_testudata(L, 2, kMatrixMeta));
  if (!a || !b)
    return luaL_error(L, "linalg: cannot compute %s %s %s (expected two matrices or vectors of one shape)",
                      kindName(L, 1), op, kindName(L, 2));
  if (a->rows != b->rows || a->cols != b->cols) return shapeMismatch(L, op, a, b);
  MatHeader* r = newMat(L, a->rows, a->cols, a->vector && b->vector, op);
  if (add)
    map(r) = map(a) + map(b);
  else
    map(r) = map(a) - map(b);
  return 1;
}
int matAdd(lua_State* L) {
  return matAddSub(L, true);
}
int matSub(lua_State* L) {
  return matAddSub(L, false);
}

int matUnm(lua_State* L) {
  MatHeader* a = checkMat(L, 1, "-");
  MatHeader* r = newLike(L, a, "-");
  map(r) = -map(a);
  return 1;
}

int matScaled(lua_State* L, MatHeader* a, double s) {
  MatHeader* r = newLike(L, a, "*");
  map(r) = map(a) * s;
  return 1;
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

int matDiv(lua_State* L) {
  MatHeader* a = static_cast<MatHeader*>(luaL_testudata(L, 1, kMatrixMeta));
  if (!a || lua_type(L, 2) != LUA_TNUMBER)
    return luaL_error(L, "linalg: cannot divide %s by %s (only by a number)", kindName(L, 1), kindName(L, 2));
  return matScaled(L, a, 1.0 / lua_tonumber(L, 2));
}

int matEq(lua_State* L) {
  auto* a = static_cast<MatHeader*>(luaL_testudata(L, 1, kMatrixMeta));
  auto* b = static_cast<MatHeader*>(luaL_testudata(L, 2, kMatrixMeta));
  lua_pushboolean(L, a && b && a->rows == b->rows && a->cols == b->cols && map(a) == map(b));
  return 1;
}

void addNumber(luaL_Buffer* b, double v) {
  char s[32];
  std::snprintf(s, sizeof s, "%.6g", v);
  luaL_addstring(b, s);
}

int matToString(lua_State* L) {
  MatHeader* a = checkMat(L, 1, "tostring");
  if (a->rows * a->cols > kMaxShownEntries) {
    lua_pushfstring(L, "linalg.%s (%dx%d)", a->vector ? "vector" : "matrix", int(a->rows), int(a->cols));
    return 1;
  }
  luaL_Buffer b;
  luaL_buffinit(L, &b);
  if (a->vector) {
    luaL_addstring(&b, "vector{");
    for (int i = 0; i < a->rows; ++i) {
      if (i) luaL_addstring(&b, ", ");
      addNumber(&b, a->data()[i]);
    }
    luaL_addstring(&b, "}");
  } else {
    luaL_addstring(&b, "matrix{");
    for (int i = 0; i < a->rows; ++i) {
      luaL_addstring(&b, i ? ", {" : "{");
      for (int j = 0; j < a->cols; ++j) {
        if (j) luaL_addstring(&b, ", ");
        addNumber(&b, a->data()[j * a->rows + i]);
      }
      luaL_addstring(&b, "}");
    }
    luaL_addstring(&b, "}");
  }
  luaL_pushresult(&b);
  return 1;
}

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

void newMeta(lua_State* L, const char* name, const luaL_Reg* metamethods, const luaL_Reg* methods) {
  luaL_newmetatable(L, name);
  luaL_setfuncs(L, metamethods, 0);
  lua_newtable(L);
  luaL_setfuncs(L, methods, 0);
  lua_setfield(L, -2, "__index");
  lua_pushstring(L, name);
  lua_setfield(L, -2, "__name");
  lua_pushboolean(L, 0);
  lua_setfield(L, -2, "__metatable");  // scripts cannot swap or read the metatable
  lua_pop(L, 1);
}

}  // namespace

int openLinalg(lua_State* L) {
  // Operators (metamethods) are written &fn: they are not functions scripts call by name.
  static const luaL_Reg matMeta[] = {{"__add", &matAdd}, {"__sub", &matSub},           {"__mul", &anyMul},
                                     {"__div", &matDiv}, {"__unm", &matUnm},           {"__eq", &matEq},
                                     {"__len", &matLen}, {"__tostring", &matToString}, {nullptr, nullptr}};
  static const luaL_Reg matMethods[] = {{"rows", matRows},
                                        {"cols", matCols},
                                        {"get", matGet},
                                        {"set", matSet},
                                        {"t", matT},
                                        {"inv", matInv},
                                        {"det", matDet},
                                        {"solve", matSolve},
                                        {"pinv", matPinv},
                                        {"svd", matSvd},
                                        {"dls", matDls},
                                        {"norm", matNorm},
                                        {"dot", matDot},
                                        {"cross", matCross},
                                        {"copy", matCopy},
                                        {"normalized", matNormalized},
                                        {"totable", matToTable},
                                        {nullptr, nullptr}};
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
  newMeta(L, kMatrixMeta, matMeta, matMethods);
  newMeta(L, kQuatMeta, quatMeta, quatMethods);
  newMeta(L, kTransformMeta, transformMeta, transformMethods);
  static const luaL_Reg fns[] = {{"matrix", linalgMatrix},       {"vector", linalgVector},
                                 {"identity", linalgIdentity},   {"zeros", linalgZeros},
                                 {"quat", linalgQuat},           {"quat_axis_angle", linalgQuatAxisAngle},
                                 {"transform", linalgTransform}, {nullptr, nullptr}};
  luaL_newlib(L, fns);
  return 1;
}

}  // namespace rm3d
