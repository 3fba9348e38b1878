// Shared by the linalg binding files (linalg_binding.cpp: the `linalg` table, helpers and `*`;
// linalg_matrix.cpp: matrices and vectors; linalg_rotation.cpp: quaternions and transforms): the
// userdata layouts and the checks. Not for use outside engine/script/linalg_*.cpp.
//
// Lua errors longjmp: every Eigen object with a destructor lives in an inner scope (`guarded`)
// that returns a status, and the error is raised after that scope is gone.
#pragma once

#include <Eigen/Dense>
#include <lua.hpp>
#include <new>

namespace rm3d::linalg {

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

inline MapM map(MatHeader* h) {
  return MapM(h->data(), h->rows, h->cols);
}
inline Quat toQuat(const QuatUd* q) {
  return Quat(q->w, q->x, q->y, q->z);
}
inline Quat toQuat(const TransformUd* t) {
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

int noMemory(lua_State* L, const char* fn);
void chargeFlops(lua_State* L, double flops);
/// A 3-vector argument: a linalg vector (or any 3 x 1 matrix) or a table {x, y, z}.
Vec3 check3(lua_State* L, int i, const char* fn);
/// A new matrix userdata on the stack (entries uninitialised); errors on a bad size.
MatHeader* newMat(lua_State* L, lua_Integer rows, lua_Integer cols, bool vector, const char* fn);
MatHeader* newLike(lua_State* L, const MatHeader* a, const char* fn);
QuatUd* newQuat(lua_State* L, const Quat& q);
TransformUd* newTransform(lua_State* L, const Quat& q, const Vec3& p);
void pushVector3(lua_State* L, const Vec3& v, const char* fn);
const char* kindName(lua_State* L, int i);
MatHeader* checkMat(lua_State* L, int i, const char* fn);
QuatUd* checkQuat(lua_State* L, int i, const char* fn);
TransformUd* checkTransform(lua_State* L, int i, const char* fn);
double checkEntry(lua_State* L, int idx, const char* fn, const char* what, int i, int j);
int shapeMismatch(lua_State* L, const char* op, const MatHeader* a, const MatHeader* b);
int needSquare(lua_State* L, const char* fn, const MatHeader* a);
/// Every `*` (matrices, quaternions and transforms mix).
int anyMul(lua_State* L);
/// A copy of a scaled by s.
int matScaled(lua_State* L, MatHeader* a, double s);
/// Raises "linalg: FN: entry (i, j) is nan; expected finite numbers" for a NaN or inf entry:
/// decompositions are only defined on finite input (Eigen's SVD of a NaN leaves garbage).
void checkFinite(lua_State* L, MatHeader* a, const char* fn);
/// Registers a metatable with methods (as __index), __name, and a hidden __metatable.
void newMeta(lua_State* L, const char* name, const luaL_Reg* metamethods, const luaL_Reg* methods);

// Constructors (the `linalg` table) and the type registrations.
int linalgMatrix(lua_State* L);
int linalgVector(lua_State* L);
int linalgIdentity(lua_State* L);
int linalgZeros(lua_State* L);
int linalgQuat(lua_State* L);
int linalgQuatAxisAngle(lua_State* L);
int linalgTransform(lua_State* L);
void openMatrixType(lua_State* L);
void openRotationTypes(lua_State* L);

}  // namespace rm3d::linalg
