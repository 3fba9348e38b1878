// Small islands' contacts solved on their own operator (docs/physics.md, "Joint solvers").
//
// The sweep moves a rigid group (a module whose motors hold) as one body, where its servos in
// fact give a little; the exact solve after each sweep puts that right, and the two alternate for
// the substep's iterations. For an island of one small tree the contact rows' own operator is
// cheap to make exactly: in the tree's coordinates (the root body's twist and each hinge's speed)
// the mass matrix H is at most 60 x 60 (PhysicsSettings::denseCoordinates), each motor's
// compliance adds its stiffness on its hinge's diagonal, and A = J H^-1 J^T, n x n for the
// island's n contact rows, is what a unit impulse of each row does to every row through the
// hinges as they are. Gauss-Seidel sweeps on A (the same bounds as the sweep's: normal rows
// clamped, each patch's tangent and rolling pairs to their circles, its twist to its bound) then
// converge without the exact solve between them; one exact solve with the motors' ratings applies
// the result. Where a motor reaches its rating there, the operator is made again without that
// motor's stiffness, and the rows swept again.
#include <BulletDynamics/Dynamics/btRigidBody.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <utility>

#include "physics/exact_solver.h"
#include "physics/hypot.h"

namespace rm3d {

namespace {

using Vec3d = Eigen::Vector3d;

// The largest tree (ExactSolver::denseCoordinates, 60 by default: a chain of up to eighteen
// SuperBots or a tree as large; each docked SuperBot adds three hinges, its docked links being one
// body). Against the alternation of sweeps and exact solves (one thread, 15 iterations, snakes of
// N SuperBots crawling, 2026-12-07, H summed by subtrees): 12 modules 18% less time a step, 15
// modules 18% less, 18 modules (60 coordinates) 8% less, 20 modules 4% less, where an island's
// rows often pass kDenseRows. (With H summed body by body, 10 modules 14 to 16% less, 12 modules 8%
// less, 15 modules 1% more: the bound was 36, and 16 before that; docs/benchmarks.md, "Chains of
// up to eighteen on their own operator".)
constexpr int kDenseNodes = 5;   // the smallest tree: two hinges and their three bodies
constexpr int kDenseRows = 64;   // the most contact rows an island may have
constexpr int kDenseRounds = 4;  // operators made again where motors reach their rating

// Four doubles side by side, for sums taken four entries at a time: each entry's products and
// sums as one at a time would make them. Two SSE2 pairs, or (FourAvx, in denseOperatorAvx) one
// AVX vector (GCC's vector extension).
typedef double Two __attribute__((vector_size(16), aligned(8)));
struct Four {
  Two lo, hi;
  [[gnu::always_inline]] static Four load(const double* p) {
    Four v;
    std::memcpy(&v.lo, p, sizeof v.lo);
    std::memcpy(&v.hi, p + 2, sizeof v.hi);
    return v;
  }
  [[gnu::always_inline]] static Four zero() {
    Four f;
    f.lo = Two{0, 0}, f.hi = Two{0, 0};
    return f;
  }
  [[gnu::always_inline]] friend Four operator*(double s, const Four& v) { return {s * v.lo, s * v.hi}; }
  [[gnu::always_inline]] friend Four operator+(double s, const Four& v) { return {s + v.lo, s + v.hi}; }
  [[gnu::always_inline]] Four& operator+=(const Four& b) {
    lo += b.lo, hi += b.hi;
    return *this;
  }
  [[gnu::always_inline]] friend Four operator-(const Four& a, const Four& b) {
    return {a.lo - b.lo, a.hi - b.hi};
  }
  [[gnu::always_inline]] void store(double* p) const {
    std::memcpy(p, &lo, sizeof lo);
    std::memcpy(p + 2, &hi, sizeof hi);
  }
  [[gnu::always_inline]] double operator[](int q) const { return q < 2 ? lo[q] : hi[q - 2]; }
};
typedef double Quad __attribute__((vector_size(32), aligned(8)));
struct FourAvx {
  Quad v;
  [[gnu::always_inline]] static FourAvx load(const double* p) {
    FourAvx f;
    std::memcpy(&f.v, p, sizeof f.v);
    return f;
  }
  [[gnu::always_inline]] static FourAvx zero() {
    FourAvx f;
    f.v = Quad{0, 0, 0, 0};
    return f;
  }
  [[gnu::always_inline]] friend FourAvx operator*(double s, const FourAvx& f) { return {s * f.v}; }
  [[gnu::always_inline]] friend FourAvx operator+(double s, const FourAvx& f) { return {s + f.v}; }
  [[gnu::always_inline]] FourAvx& operator+=(const FourAvx& b) {
    v += b.v;
    return *this;
  }
  [[gnu::always_inline]] friend FourAvx operator-(const FourAvx& a, const FourAvx& b) { return {a.v - b.v}; }
  [[gnu::always_inline]] void store(double* p) const { std::memcpy(p, &v, sizeof v); }
  [[gnu::always_inline]] double operator[](int q) const { return v[q]; }
};

// Runs fn.template operator()<G>(k) over groups of four entries from `begin` (a multiple of four's
// start) while k < end: G = 4 groups (sixteen entries) at a time where there are, then 2, then 1.
// With G fixed its G sums are held in registers side by side, each summed as it would be alone.
template <class Fn>
[[gnu::always_inline]] inline void inGroups(int begin, int end, Fn&& fn) {
  int k = begin;
  for (; k + 12 < end; k += 16) fn.template operator()<4>(k);
  for (; k + 4 < end; k += 8) fn.template operator()<2>(k);
  for (; k < end; k += 4) fn.template operator()<1>(k);
}

}  // namespace

/// The most coordinates of a tree the operator takes: the setting (the primary's), within
/// [0, kDenseCoordinatesMax].
int ExactSolver::denseBound() const {
  return std::clamp(m_shared->denseCoordinates, 0, kDenseCoordinatesMax);
}

/// At a solver group's setup, after planSettling: the islands whose contacts the dense solve will
/// take at the first iteration (each one small tree and its rows, as denseIsland asks), so that
/// buildGroups makes no sweep data for them (m_slotDense, m_rowDense).
void ExactSolver::planDenseIslands() {
  const int slots = int(m_slotSettle.size());
  const int nc = m_tmpSolverContactConstraintPool.size();
  m_slotDense.assign(size_t(slots), 0);
  m_rowDense.assign(size_t(nc + m_patchRows.size()), 0);
  if (slots == 0 || !m_shared->denseIslands || !m_settling || !m_groupHasJoints) return;
  // Each slot's items (in sweep order) and its count of clusters.
  const int items = int(m_itemSlot.size());
  m_denseSlotStart.assign(size_t(slots) + 1, 0);
  for (int t = 0; t < items; ++t)
    if (const int s = m_itemSlot[size_t(t)]; s >= 0) ++m_denseSlotStart[size_t(s) + 1];
  for (int s = 0; s < slots; ++s) m_denseSlotStart[size_t(s) + 1] += m_denseSlotStart[size_t(s)];
  m_denseSlotItems.resize(size_t(m_denseSlotStart[size_t(slots)]));
  std::vector<int>& fill = m_denseSlotClusters;
  fill.assign(m_denseSlotStart.begin(), m_denseSlotStart.end() - 1);
  for (int t = 0; t < items; ++t)
    if (const int s = m_itemSlot[size_t(t)]; s >= 0) m_denseSlotItems[size_t(fill[size_t(s)]++)] = t;
  m_denseSlotClusters.assign(size_t(slots), 0);
  for (int ci = m_groupBegin; ci < int(m_clusters.size()); ++ci)
    if (const int s = clusterSlot(m_clusters[size_t(ci)]); s >= 0) ++m_denseSlotClusters[size_t(s)];
  const int captures = int(m_groupCaptures.size());
  for (int ci = m_groupBegin; ci < int(m_clusters.size()); ++ci) {
    const Cluster& c = m_clusters[size_t(ci)];
    const int s = clusterSlot(c);
    if (s < 0 || m_slotSettle[size_t(s)] != Settle::Open || m_denseSlotClusters[size_t(s)] != 1) continue;
    // (A tree of one hinge, an ATRON's, settles in two sweeps: its operator costs more than it
    // saves, 12 to 17% more of atrons_275's physics.)
    const int nodes = c.end - c.begin;
    if (c.split || c.loopEnd > c.loopBegin || nodes < kDenseNodes || nodes > 2 * denseBound()) continue;
    if (denseShape(c) == 0) continue;
    // Every row on this tree's bodies or the static world, and not too many of them. (Not through
    // rowSide: the groups it reads are made after this.)
    auto ours = [&](const btSolverConstraint& row) {
      for (const int sid : {row.m_solverBodyIdA, row.m_solverBodyIdB}) {
        if (!m_tmpSolverBodyPool[sid].m_originalBody) continue;
        const int index = sid < int(m_sidToBody.size()) ? m_sidToBody[size_t(sid)] : -1;
        if (index < 0 || m_bodyCluster[size_t(index)] != ci) return false;
      }
      return true;
    };
    int n = 0;
    bool taken = true;
    for (int k = m_denseSlotStart[size_t(s)]; k < m_denseSlotStart[size_t(s) + 1] && taken; ++k) {
      const int t = m_denseSlotItems[size_t(k)];
      if (t < captures) {
        taken = false;
      } else if (t < captures + nc) {
        btSolverConstraint& row = m_tmpSolverContactConstraintPool[m_orderTmpConstraintPool[t - captures]];
        if (row.m_jacDiagABInv == 0) continue;  // (not swept either)
        taken = ours(row);
        ++n;
      } else {
        const PatchRows& pr = m_groupPatches[size_t(t - captures - nc)];
        for (int k2 = 0; k2 < (pr.roll ? 5 : 3) && taken; ++k2) taken = ours(m_patchRows[pr.row + k2]);
        n += pr.roll ? 5 : 3;
      }
    }
    if (!taken || n == 0 || n > kDenseRows) continue;
    m_slotDense[size_t(s)] = 1;
    forSlotRows(s, [&](int i) { m_rowDense[size_t(i)] = 1; });
  }
}

/// fn(i) for each row (index into m_rowExtra) of slot s's contact and patch items (a slot the
/// dense solve takes has no capture item).
template <class Fn>
void ExactSolver::forSlotRows(int s, const Fn& fn) {
  const int nc = m_tmpSolverContactConstraintPool.size();
  const int captures = int(m_groupCaptures.size());
  for (int k = m_denseSlotStart[size_t(s)]; k < m_denseSlotStart[size_t(s) + 1]; ++k) {
    const int t = m_denseSlotItems[size_t(k)];
    if (t < captures) continue;
    if (t < captures + nc) {
      fn(m_orderTmpConstraintPool[t - captures]);
    } else {
      const PatchRows& pr = m_groupPatches[size_t(t - captures - nc)];
      for (int k2 = 0; k2 < (pr.roll ? 5 : 3); ++k2) fn(nc + pr.row + k2);
    }
  }
}

/// Whether body b (of this group) is on an island planDenseIslands gave to the dense solve.
bool ExactSolver::denseBody(int b) const {
  const int ci = m_bodyCluster[size_t(b)];
  const int s = ci >= 0 ? clusterSlot(m_clusters[size_t(ci)]) : -1;
  return s >= 0 && m_slotDense[size_t(s)];
}

/// At the substep's first iteration, before its sweep: every island planDenseIslands chose has
/// its contacts solved here, and is then settled (swept and solved no more). One it chose and
/// that is left to the sweeps after all (its mass matrix not positive definite) has its rows'
/// sweep data made now, with its bodies ungrouped.
void ExactSolver::solveDenseIslands(int sweeps) {
  for (int ci = m_groupBegin; ci < int(m_clusters.size()); ++ci) {
    Cluster& c = m_clusters[size_t(ci)];
    const int s = clusterSlot(c);
    if (s < 0 || !m_slotDense[size_t(s)]) continue;
    const int b = m_denseSlotStart[size_t(s)];
    if (denseIsland(c, m_denseSlotItems.data() + b, m_denseSlotStart[size_t(s) + 1] - b, sweeps)) {
      m_slotSettle[size_t(s)] = Settle::Settled;
      continue;
    }
    m_slotDense[size_t(s)] = 0;
    forSlotRows(s, [&](int i) { rowData(i, true); });
  }
}

/// Whether cluster c's tree is one the operator takes (a body at its root, no hinge to the static
/// world, at most kDenseCoordinatesMax coordinates), its bodies' and hinges' places noted
/// (m_denseNodeIndex); its coordinates' count, or 0.
int ExactSolver::denseShape(const Cluster& c) {
  if (m_nodes[size_t(c.begin)].body < 0) return 0;
  const int nodes = c.end - c.begin;
  if (int(m_denseNodeIndex.size()) < nodes) m_denseNodeIndex.resize(size_t(nodes));
  int bodies = 0, nu = 6;
  for (int k = c.begin; k < c.end; ++k) {
    const Node& nd = m_nodes[size_t(k)];
    if (nd.body >= 0) {
      m_denseNodeIndex[size_t(k - c.begin)] = bodies++;
      continue;
    }
    const Row& r = row(nd.joint);
    if (r.na < 0 || r.nb < 0) return 0;
    m_denseNodeIndex[size_t(k - c.begin)] = nu++;
  }
  return nu <= denseBound() ? nu : 0;
}

/// The operator of the contact rows m_denseRows[0, n) on cluster c's tree (of denseShape's form,
/// nu coordinates) into m_denseA (n x n); false where its mass matrix is not positive definite.
/// F: four doubles side by side (Four, or FourAvx inlined into denseOperatorAvx).
template <class F>
bool ExactSolver::denseOperatorOf(const Cluster& c, int n, int nu) {
  using A = ExactJoint::Axial;
  const int bodies = (c.end - c.begin + 1) / 2;  // (a tree of bodies and hinges: one more body)
  constexpr int kCols = kDenseCoordinatesMax + 1;
  // H by its subtrees' inertias (the composite-rigid-body algorithm), in the world's axes about
  // the root body's centre: each coordinate's twist S_k there (the root's: its centre's velocity
  // and its angular velocity; a hinge's: the rotation about its axis of the bodies past it), and
  // H's entry (j, k), j on k's path from the root, S_j against the momentum I_k S_k of the bodies
  // that k moves (I_k: their inertia together; the whole tree's for the root's six). A body's
  // columns (m_denseCols: its count, then the root's six and the hinges' on its path, increasing,
  // as the hinges' columns follow the tree's order) are the only ones its rows touch.
  const int hs = (nu + 3) & ~3;  // (H's rows: the sums below take four entries at a time)
  if (m_denseH.size() < size_t(nu * hs)) m_denseH.resize(size_t(nu * hs));
  if (m_denseS.size() < size_t(6 * nu)) m_denseS.resize(size_t(6 * nu));
  if (m_denseBody.size() < size_t(16 * bodies)) m_denseBody.resize(size_t(16 * bodies));
  if (m_denseCols.size() < size_t(bodies * kCols)) m_denseCols.resize(size_t(bodies * kCols));
  double* H = m_denseH.data();
  std::fill_n(H, nu * hs, 0.0);
  double* S = m_denseS.data();
  double* B = m_denseBody.data();  // per body: its centre (3), then its subtree's m, h = sum m c (3), I (9)
  auto get3 = [](const double* p) { return Vec3d(p[0], p[1], p[2]); };
  auto put3 = [](double* p, const Vec3d& v) { p[0] = v.x(), p[1] = v.y(), p[2] = v.z(); };
  using Matrix3dRef = Eigen::Map<const Eigen::Matrix3d>;
  for (int k = c.begin; k < c.end; ++k) {
    const Node& nd = m_nodes[size_t(k)];
    if (nd.body < 0) continue;
    const int bi = m_denseNodeIndex[size_t(k - c.begin)];
    double* bd = B + 16 * bi;
    int* cols = m_denseCols.data() + bi * kCols;
    if (k == c.begin) {
      put3(bd, Vec3d::Zero());
      std::fill_n(S, 36, 0.0);
      for (int i = 0; i < 6; ++i) S[6 * i + i] = 1, cols[1 + i] = i;
      cols[0] = 6;
    } else {
      const Node& jn = m_nodes[size_t(nd.parent)];
      const Row& r = row(jn.joint);
      const int pi = m_denseNodeIndex[size_t(jn.parent - c.begin)];
      const int* pcols = m_denseCols.data() + pi * kCols;
      // The child's centre is its parent's and r_a - r_b (b the child) or r_b - r_a (a the child);
      // the hinge turns it at w = z (b the child) or -z about the pivot p, at the root's centre
      // v = p x w.
      const bool childIsB = jn.parentIsA;
      const Vec3d centre = get3(B + 16 * pi) + (childIsB ? Vec3d(r.ra - r.rb) : Vec3d(r.rb - r.ra));
      put3(bd, centre);
      const int pm = pcols[0];
      for (int a = 1; a <= pm; ++a) cols[a] = pcols[a];
      const int q = m_denseNodeIndex[size_t(nd.parent - c.begin)];
      cols[pm + 1] = q;
      cols[0] = pm + 1;
      const Vec3d w = childIsB ? Vec3d(r.frame.col(2)) : Vec3d(-r.frame.col(2));
      const Vec3d pivot = centre + (childIsB ? r.rb : r.ra);
      put3(S + 6 * q, pivot.cross(w));
      put3(S + 6 * q + 3, w);
    }
    // The body's own m, m c and inertia about the root's centre, I_c + m (|c|^2 - c c^T).
    const Body& b = m_bodies[size_t(nd.body)];
    const double m = 1.0 / b.invMass;
    const Vec3d centre = get3(bd);
    bd[3] = m;
    put3(bd + 4, m * centre);
    Eigen::Map<Eigen::Matrix3d>(bd + 7) =
        b.inertia + m * (centre.squaredNorm() * Eigen::Matrix3d::Identity() - centre * centre.transpose());
  }
  // Each subtree's: its children's added to each body, the last first.
  for (int k = c.end - 1; k > c.begin; --k) {
    const Node& nd = m_nodes[size_t(k)];
    if (nd.body < 0) continue;
    const double* from = B + 16 * m_denseNodeIndex[size_t(k - c.begin)];
    double* to = B + 16 * m_denseNodeIndex[size_t(m_nodes[size_t(nd.parent)].parent - c.begin)];
    for (int i = 3; i < 16; ++i) to[i] += from[i];
  }
  // Column k of H: p = m v + w x h and L = h x v + I w of its bodies moving at S_k = (v, w), then
  // each entry on its path S_j . (p, L).
  auto column = [&](int k, const double* bd, const int* path, int count) {
    const Vec3d v = get3(S + 6 * k), w = get3(S + 6 * k + 3), h = get3(bd + 4);
    const Vec3d p = bd[3] * v + w.cross(h);
    const Vec3d L = h.cross(v) + Matrix3dRef(bd + 7) * w;
    for (int t = 0; t < count; ++t) {
      const int j = path[t];
      const double* sj = S + 6 * j;
      H[j * hs + k] =
          sj[0] * p.x() + sj[1] * p.y() + sj[2] * p.z() + sj[3] * L.x() + sj[4] * L.y() + sj[5] * L.z();
    }
  };
  static constexpr int kRootCols[6] = {0, 1, 2, 3, 4, 5};
  const double* root = B + 16 * m_denseNodeIndex[0];
  for (int k = 0; k < 6; ++k) column(k, root, kRootCols, k + 1);
  for (int k = c.begin + 1; k < c.end; ++k) {
    const Node& nd = m_nodes[size_t(k)];
    if (nd.body < 0) continue;
    const int bi = m_denseNodeIndex[size_t(k - c.begin)];
    const int* cols = m_denseCols.data() + bi * kCols;
    column(cols[cols[0]], B + 16 * bi, cols + 1, cols[0]);
  }
  // Each motor's stiffness on its hinge (the tree's axial row: compliance, or hard at a limit).
  for (int k = c.begin; k < c.end; ++k) {
    const Node& nd = m_nodes[size_t(k)];
    if (nd.joint < 0 || !row(nd.joint).axialActive) continue;
    const ExactJoint& e = m_shared->joints[size_t(nd.joint)];
    const int q = m_denseNodeIndex[size_t(k - c.begin)];
    H[q * hs + q] += 1.0 / (e.state == A::Motor ? e.compliance + kRegularisation : kRegularisation);
  }
  // H = U^T U, U upper triangular, in place in H's upper triangle, a row of U at a time: H's row
  // less the products of the rows of U before it, in their order, four entries at a time (from the
  // group of four its diagonal is in: what lands left of the diagonal, and past the last column, is
  // finite and not read; up to four groups held in registers over the rows
  // before), then scaled.
  for (int i = 0; i < nu; ++i) {
    double* hi = H + i * hs;
    inGroups(i & ~3, nu, [&]<int G>(int k0) {
      F h[G];
      for (int g = 0; g < G; ++g) h[g] = F::load(hi + k0 + 4 * g);
      for (int j = 0; j < i; ++j) {
        const double u = H[j * hs + i];
        const double* uj = H + j * hs + k0;
        for (int g = 0; g < G; ++g) h[g] = h[g] - u * F::load(uj + 4 * g);
      }
      for (int g = 0; g < G; ++g) h[g].store(hi + k0 + 4 * g);
    });
    const double d = hi[i];
    if (!(d > 0)) return false;
    const double uii = std::sqrt(d);
    hi[i] = uii;
    const double inv = 1.0 / uii;
    for (int k = i + 1; k < nu; ++k) hi[k] *= inv;
  }
  // Each row's Jacobian in the tree's coordinates, J_i = S_k . (n, r x n + c_b x n) over its
  // sides' bodies (the row's wrench about the root's centre) on each column k of the body's, then
  // Y = U^-T J^T (nu x n, a coordinate's entries for all rows together, in rows of four: the
  // substitution runs across the rows, not down one row's chain); A = Y^T Y.
  const int n4 = (n + 3) & ~3;
  // (Four entries of slack: A's sums below load four from a row's entry i, past the last row's end.)
  if (m_denseY.size() < size_t(nu * n4 + 4)) m_denseY.resize(size_t(nu * n4 + 4));
  double* Y = m_denseY.data();
  std::fill_n(Y, nu * n4, 0.0);
  for (int i = 0; i < n; ++i)
    for (const RowSide& side : m_denseRows[size_t(i)].sides) {
      if (!side.body->m_originalBody) continue;
      const int node = m_nodeOfBody[size_t(side.index)];
      const int bi = m_denseNodeIndex[size_t(node - c.begin)];
      const int* cols = m_denseCols.data() + bi * kCols;
      const Vec3d f(side.n->x(), side.n->y(), side.n->z());
      const Vec3d moment = Vec3d(side.rc->x(), side.rc->y(), side.rc->z()) + get3(B + 16 * bi).cross(f);
      for (int a = 0; a < cols[0]; ++a) {
        const double* sk = S + 6 * cols[1 + a];
        Y[cols[1 + a] * n4 + i] += sk[0] * f.x() + sk[1] * f.y() + sk[2] * f.z() + sk[3] * moment.x() +
                                   sk[4] * moment.y() + sk[5] * moment.z();
      }
    }
  // (Up to sixteen rows at a time held in registers over the coordinates before: each entry the
  // same products and differences in the same order, without a load and store per coordinate.)
  for (int col = 0; col < nu; ++col) {
    double* y = Y + col * n4;
    const double inv = 1.0 / H[col * hs + col];
    inGroups(0, n, [&]<int G>(int i0) {
      F v[G];
      for (int g = 0; g < G; ++g) v[g] = F::load(y + i0 + 4 * g);
      for (int k = 0; k < col; ++k) {
        const double l = H[k * hs + col];
        const double* yk = Y + k * n4 + i0;
        for (int g = 0; g < G; ++g) v[g] = v[g] - l * F::load(yk + 4 * g);
      }
      for (int g = 0; g < G; ++g) (inv * v[g]).store(y + i0 + 4 * g);
    });
  }
  // A = Y^T Y, each entry's sum over the coordinates in their order from 0.0 + its first product,
  // four entries of a row at a time (up to four such sums side by side), each entry written to both
  // halves.
  double* op = m_denseA.data();
  auto put = [&](int i, int j0, const F& acc) {
    for (int k = 0; k < 4 && j0 + k < n; ++k) op[i * n + j0 + k] = op[(j0 + k) * n + i] = acc[k];
  };
  for (int i = 0; i < n; ++i)
    inGroups(i, n, [&]<int G>(int j0) {
      F acc[G];
      for (int g = 0; g < G; ++g) acc[g] = 0.0 + Y[i] * F::load(Y + j0 + 4 * g);
      for (int col = 1; col < nu; ++col) {
        const double* yc = Y + col * n4;
        const double yi = yc[i];
        for (int g = 0; g < G; ++g) acc[g] += yi * F::load(yc + j0 + 4 * g);
      }
      for (int g = 0; g < G; ++g) put(i, j0 + 4 * g, acc[g]);
    });
  return true;
}

/// denseOperatorOf, by the CPU's widest vectors (the same bits).
bool ExactSolver::denseOperator(const Cluster& c, int n, int nu) {
  return m_avx ? denseOperatorAvx(c, n, nu) : denseOperatorOf<Four>(c, n, nu);
}

bool ExactSolver::denseOperatorAvx(const Cluster& c, int n, int nu) {
  return denseOperatorOf<FourAvx>(c, n, nu);
}

/// denseSweepsOf, its passes over the rows' velocities by the CPU's widest vectors (element by
/// element: the same bits).
void ExactSolver::denseSweeps(int n, int sweeps) {
  if (m_avx)
    denseSweepsAvx(n, sweeps);
  else
    denseSweepsOf(n, sweeps);
}

void ExactSolver::denseSweepsAvx(int n, int sweeps) {
  denseSweepsOf(n, sweeps);
}

/// Up to `sweeps` Gauss-Seidel sweeps on m_denseA from the impulses in m_denseLam (the velocities
/// in m_denseVel), in the sweep's order and with its bounds; ends early where no impulse changed
/// by more than the settling's threshold (kSweepSettled).
void ExactSolver::denseSweepsOf(int n, int sweeps) {
  double* lam = m_denseLam.data();
  double* vel = m_denseVel.data();
  const double* A = m_denseA.data();
  auto set = [&](int r, double next) {
    const double d = next - lam[r];
    if (d == 0) return;
    lam[r] = next;
    m_denseRows[size_t(r)].c->m_appliedImpulse = btScalar(next);  // (read by patchLoad)
    const double* col = A + size_t(r * n);                        // (symmetric: row r)
    for (int j = 0; j < n; ++j) vel[j] += col[j] * d;
  };
  // Each row's target velocity, compliance and 1 / (its diagonal + compliance) (0: the row
  // cannot move), so that the sweeps' chain of updates multiplies instead of divides.
  double* rx = m_denseRowX.data();
  for (int r = 0; r < n; ++r) {
    const double* x = &m_rowExtra[size_t(4 * m_denseRows[size_t(r)].extra)];
    const double diag = A[size_t(r * n + r)] + x[1];
    rx[3 * r] = x[0], rx[3 * r + 1] = x[1], rx[3 * r + 2] = diag > 0 ? 1 / diag : 0;
  }
  // Row r's impulse where its velocity meets its target, the others held.
  auto target = [&](int r) {
    const double* x = rx + 3 * r;
    return lam[r] + (x[0] - x[1] * lam[r] - vel[r]) * x[2];
  };
  for (int sweep = 0; sweep < sweeps; ++sweep) {
    double largest = 0;
    // A patch's load, made at its first unit and kept for the next ones of the same patch (its
    // tangent, twist and rolling units follow one another and change none of its normal rows).
    int loadOf = -1;
    std::pair<double, double> load;
    for (const DenseUnit& u : m_denseUnits) {
      const int r = u.row;
      const double before0 = lam[r];
      if (u.kind == DenseUnit::Normal) {
        const btSolverConstraint& c = *m_denseRows[size_t(r)].c;
        set(r, std::clamp(target(r), double(c.m_lowerLimit), double(c.m_upperLimit)));
        loadOf = -1;
        largest = std::max(largest, (lam[r] - before0) * (lam[r] - before0));
        continue;
      }
      const PatchRows& pr = m_groupPatches[size_t(u.patch)];
      if (loadOf != u.patch) load = patchLoad(pr), loadOf = u.patch;
      const auto [normalSum, twistArm] = load;
      // A pair, each row then the other, then both scaled back to their circle, and after the
      // tangent pair the patch's twist, clamped. The velocities are changed in one pass for the
      // unit's rows, each taking the rows' changes in the order one pass a change would (the same
      // sums); a row's target reads its own velocity with the changes before it added.
      const double bound = (u.kind == DenseUnit::Tangent ? pr.mu : pr.rolling) * normalSum;
      const double before1 = lam[r + 1];
      const double* col0 = A + size_t(r * n);
      const double* col1 = A + size_t((r + 1) * n);
      const double* x0 = rx + 3 * r;
      const double* x1 = rx + 3 * (r + 1);
      double a = before0 + (x0[0] - x0[1] * before0 - vel[r]) * x0[2];
      const double d0 = a - before0;
      const double v1 = vel[r + 1] + col0[r + 1] * d0;
      double b = before1 + (x1[0] - x1[1] * before1 - v1) * x1[2];
      const double d1 = b - before1;
      // (The square root only for a pair outside its circle: at rest most are inside.)
      double d2 = 0, d3 = 0;  // (the scaling's changes)
      const bool scaled = a * a + b * b > bound * bound;
      if (scaled) {
        const double scale = bound / hypotInline(a, b);
        const double as = a * scale, bs = b * scale;
        d2 = as - a, d3 = bs - b;
        a = as, b = bs;
      }
      const double e0 = a - before0, e1 = b - before1;
      lam[r] = a, lam[r + 1] = b;
      m_denseRows[size_t(r)].c->m_appliedImpulse = btScalar(a);
      m_denseRows[size_t(r + 1)].c->m_appliedImpulse = btScalar(b);
      largest = std::max(largest, e0 * e0 + e1 * e1);
      auto afterPair = [&](int j) {  // (row j's velocity with the pair's changes)
        const double v = vel[j] + col0[j] * d0 + col1[j] * d1;
        return scaled ? v + col0[j] * d2 + col1[j] * d3 : v;
      };
      // (The passes below written out for each case: one loop over afterPair, the scaling's test
      // inside it, made the sweeps 4 to 9% slower.)
      if (u.kind == DenseUnit::Rolling) {
        if (scaled)
          for (int j = 0; j < n; ++j)
            vel[j] = vel[j] + col0[j] * d0 + col1[j] * d1 + col0[j] * d2 + col1[j] * d3;
        else
          for (int j = 0; j < n; ++j) vel[j] = vel[j] + col0[j] * d0 + col1[j] * d1;
        continue;
      }
      const double twistBound = pr.mu * twistArm + pr.spin * normalSum;
      const double before2 = lam[r + 2];
      const double* col2 = A + size_t((r + 2) * n);
      const double* x2 = rx + 3 * (r + 2);
      const double t =
          std::clamp(before2 + (x2[0] - x2[1] * before2 - afterPair(r + 2)) * x2[2], -twistBound, twistBound);
      const double e2 = t - before2;
      lam[r + 2] = t;
      m_denseRows[size_t(r + 2)].c->m_appliedImpulse = btScalar(t);
      largest = std::max(largest, e2 * e2);
      if (scaled)
        for (int j = 0; j < n; ++j)
          vel[j] = vel[j] + col0[j] * d0 + col1[j] * d1 + col0[j] * d2 + col1[j] * d3 + col2[j] * e2;
      else
        for (int j = 0; j < n; ++j) vel[j] = vel[j] + col0[j] * d0 + col1[j] * d1 + col2[j] * e2;
    }
    if (largest < kSweepSettled) break;
  }
}

/// Island of cluster c (its sweep items `items`): its contacts solved on their own operator, true
/// if they were; else the island is left to the sweeps (untouched, but for one exact solve where
/// its mass matrix was not positive definite).
bool ExactSolver::denseIsland(Cluster& c, const int* items, int count, int sweeps) {
  const int nc = m_tmpSolverContactConstraintPool.size();
  const int captures = int(m_groupCaptures.size());
  const int ci = int(&c - m_clusters.data());
  m_denseRows.clear();
  m_denseUnits.clear();
  // Every row's sides: the static world, or a body of this cluster (moved by the row directly,
  // not through a rigid group).
  auto addRow = [&](btSolverConstraint& row, int extra) {
    DenseRow d{&row, extra, {rowSide(row, 0), rowSide(row, 1)}};
    for (RowSide& side : d.sides) {
      side.group = -1;
      side.push = nullptr;
      if (side.body->m_originalBody && (side.index < 0 || m_bodyCluster[size_t(side.index)] != ci))
        return false;
    }
    m_denseRows.push_back(d);
    return true;
  };
  for (int i = 0; i < count; ++i) {
    const int t = items[i];
    if (t < captures) return false;
    if (t < captures + nc) {
      const int r = m_orderTmpConstraintPool[t - captures];
      if (m_rowExtra[size_t(4 * r + 2)] == 0) continue;  // (not swept either)
      m_denseUnits.push_back({DenseUnit::Normal, int(m_denseRows.size()), -1});
      if (!addRow(m_tmpSolverContactConstraintPool[r], r)) return false;
      continue;
    }
    const int p = t - captures - nc;
    const PatchRows& pr = m_groupPatches[size_t(p)];
    const int first = int(m_denseRows.size());
    m_denseUnits.push_back({DenseUnit::Tangent, first, p});
    if (pr.roll) m_denseUnits.push_back({DenseUnit::Rolling, first + 3, p});
    for (int k = 0; k < (pr.roll ? 5 : 3); ++k)
      if (!addRow(m_patchRows[pr.row + k], nc + pr.row + k)) return false;
  }
  const int n = int(m_denseRows.size());
  const int nu = n > 0 && n <= kDenseRows ? denseShape(c) : 0;
  if (nu == 0) return false;
  for (std::vector<double>* v : {&m_denseU0, &m_denseVel, &m_denseLam, &m_denseStart})
    if (v->size() < size_t(n)) v->resize(size_t(n));
  if (m_denseA.size() < size_t(n * n)) m_denseA.resize(size_t(n * n));
  if (m_denseRowX.size() < size_t(3 * n)) m_denseRowX.resize(size_t(3 * n));

  for (int round = 0; round < kDenseRounds; ++round) {
    // The velocities the hinges make of the substep's start (the warm start included), and the
    // rows' operator at the motors' present states.
    if (c.dirty)
      factor(c, true);  // (and the solve, in the factor's passes: a tree without loops)
    else
      solve(c, true);
    if (!denseOperator(c, n, nu)) {
      // (Its mass matrix not positive definite: the sweeps take the rest, from here; never met.)
      if (round == 0) return false;
      c.clamped = true;
      break;
    }
    for (int j = 0; j < n; ++j) {
      m_denseU0[size_t(j)] = m_denseVel[size_t(j)] = rowVelocity(m_denseRows[size_t(j)].sides);
      m_denseLam[size_t(j)] = m_denseStart[size_t(j)] = m_denseRows[size_t(j)].c->m_appliedImpulse;
    }
    denseSweeps(n, sweeps);
    // The impulses' changes to the bodies, and the exact solve with the motors' ratings.
    for (int j = 0; j < n; ++j)
      applyRowImpulse(m_denseRows[size_t(j)].sides, m_denseLam[size_t(j)] - m_denseStart[size_t(j)]);
    const bool before = c.clamped;
    c.clamped = false;
    clusterIteration(c, true);
    const bool clamped = c.clamped;
    // A motor fixed at its rating in the last round leaves the contacts to the sweeps after the
    // iterations (finishJoints), as elsewhere.
    c.clamped = before || (clamped && round + 1 == kDenseRounds);
    if (!clamped) break;
  }
  ++m_denseIslands;
  return true;
}

}  // namespace rm3d
