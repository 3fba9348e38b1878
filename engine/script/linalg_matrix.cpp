// linalg matrices and vectors (the userdata "linalg.matrix"): constructors, methods and
// operators but `*` (linalg_binding.cpp).
#include <Eigen/Cholesky>
#include <Eigen/SVD>
#include <cmath>
#include <limits>

#include "script/linalg_internal.h"

namespace rm3d::linalg {

namespace {

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
  checkFinite(L, a, "inv");
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
  checkFinite(L, a, "det");
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
  checkFinite(L, a, "solve");
  checkFinite(L, b, "solve");
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
  checkFinite(L, a, "pinv");
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
  checkFinite(L, a, "svd");
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
  checkFinite(L, a, "dls");
  checkFinite(L, b, "dls");
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

}  // namespace

int matScaled(lua_State* L, MatHeader* a, double s) {
  MatHeader* r = newLike(L, a, "*");
  map(r) = map(a) * s;
  return 1;
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

void openMatrixType(lua_State* L) {
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
  newMeta(L, kMatrixMeta, matMeta, matMethods);
}

}  // namespace rm3d::linalg
