// The exact solver's tree solve, node by node: the three products of its 6 x 6 blocks, four rows
// at a time; and, on AVX, its factor's two steps a node (its pivot inverted, its share passed to
// its parent's) and a hinge's residual. Each element takes the same operations in the same order
// as Eigen's fixed-size products (coefficient-based, no fused multiply-add), so the result is the
// same, bit for bit: the solve's compiled for SSE2 or AVX, the others as node_eigen.h's Eigen
// forms. ExactSolver runs the AVX build where the CPU has it.
#pragma once

namespace rm3d::node_products {

// Four and two doubles, from any double's address.
typedef double V4 __attribute__((vector_size(32), aligned(8), may_alias));
typedef double V2 __attribute__((vector_size(16), aligned(8), may_alias));

struct Col6 {  // six rows: four and two
  V4 lo;
  V2 hi;
};

/// Column k of a 6 x 6 column-major m, times s.
[[gnu::always_inline]] inline Col6 column(const double* m, int k, double s) {
  const V4 s4 = {s, s, s, s};
  const V2 s2 = {s, s};
  return {*reinterpret_cast<const V4*>(m + 6 * k) * s4, *reinterpret_cast<const V2*>(m + 6 * k + 4) * s2};
}

[[gnu::always_inline]] inline Col6 operator+(const Col6& a, const Col6& b) {
  return {a.lo + b.lo, a.hi + b.hi};
}

/// m v for a 6 x 6 column-major m, as Eigen's `m * v`: each element summed over the columns in
/// order, ((m(i,0) v0 + m(i,1) v1) + ...) + m(i,5) v5.
[[gnu::always_inline]] inline Col6 product(const double* m, const double* v) {
  Col6 r = column(m, 0, v[0]);
  for (int k = 1; k < 6; ++k) r = r + column(m, k, v[k]);
  return r;
}

/// m^T v for a 6 x 6 column-major m, as Eigen's `m.transpose() * v`: element i is the dot
/// product of column i and v taken in pairs, (p0 + (p2 + p4)) + (p1 + (p3 + p5)) with p_k =
/// m(k,i) v_k.
[[gnu::always_inline]] inline Col6 transposedProduct(const double* m, const double* v) {
  const V4 vlo = *reinterpret_cast<const V4*>(v);
  const V2 vhi = *reinterpret_cast<const V2*>(v + 4);
  double s[6];
  for (int i = 0; i < 6; ++i) {
    const V4 lo = *reinterpret_cast<const V4*>(m + 6 * i) * vlo;      // p0 p1 p2 p3
    const V2 hi = *reinterpret_cast<const V2*>(m + 6 * i + 4) * vhi;  // p4 p5
    const V2 pairs = V2{lo[0], lo[1]} + (V2{lo[2], lo[3]} + hi);      // the even sum, the odd sum
    s[i] = pairs[0] + pairs[1];
  }
  return {V4{s[0], s[1], s[2], s[3]}, V2{s[4], s[5]}};
}

[[gnu::always_inline]] inline void store(double* x, const Col6& v) {
  *reinterpret_cast<V4*>(x) = v.lo;
  *reinterpret_cast<V2*>(x + 4) = v.hi;
}

/// x -= v
[[gnu::always_inline]] inline void subtract(double* x, const Col6& v) {
  *reinterpret_cast<V4*>(x) = *reinterpret_cast<const V4*>(x) - v.lo;
  *reinterpret_cast<V2*>(x + 4) = *reinterpret_cast<const V2*>(x + 4) - v.hi;
}

/// m (6 x 6, column-major) exactly symmetric: each element and its mirror set to 0.5 (m(r, c) +
/// m(c, r)), the diagonal too (0.5 (x + x) is x but for a denormal that flushes), as that loop
/// would, by 4 x 4, 4 x 2 and 2 x 2 blocks.
[[gnu::always_inline]] inline void symmetrise(double* m) {
  V4 c[6];
  V2 h[6];
  for (int k = 0; k < 6; ++k) {
    c[k] = *reinterpret_cast<const V4*>(m + 6 * k);
    h[k] = *reinterpret_cast<const V2*>(m + 6 * k + 4);
  }
  const V4 half = {0.5, 0.5, 0.5, 0.5};
  // The top left 4 x 4: rows 0-3 as vectors over columns 0-3.
  const V4 t0 = __builtin_shufflevector(c[0], c[1], 0, 4, 2, 6),
           t1 = __builtin_shufflevector(c[0], c[1], 1, 5, 3, 7);
  const V4 t2 = __builtin_shufflevector(c[2], c[3], 0, 4, 2, 6),
           t3 = __builtin_shufflevector(c[2], c[3], 1, 5, 3, 7);
  const V4 r[4] = {__builtin_shufflevector(t0, t2, 0, 1, 4, 5), __builtin_shufflevector(t1, t3, 0, 1, 4, 5),
                   __builtin_shufflevector(t0, t2, 2, 3, 6, 7), __builtin_shufflevector(t1, t3, 2, 3, 6, 7)};
  // Rows 4 and 5 over columns 0-3, against columns 4 and 5's rows 0-3.
  const V4 v02 = {h[0][0], h[0][1], h[2][0], h[2][1]}, v13 = {h[1][0], h[1][1], h[3][0], h[3][1]};
  const V4 s4 = half * (c[4] + __builtin_shufflevector(v02, v13, 0, 4, 2, 6));
  const V4 s5 = half * (c[5] + __builtin_shufflevector(v02, v13, 1, 5, 3, 7));
  for (int k = 0; k < 4; ++k) {
    *reinterpret_cast<V4*>(m + 6 * k) = half * (c[k] + r[k]);
    *reinterpret_cast<V2*>(m + 6 * k + 4) = V2{s4[k], s5[k]};
  }
  *reinterpret_cast<V4*>(m + 24) = s4;
  *reinterpret_cast<V4*>(m + 30) = s5;
  const double m45 = 0.5 * (h[4][1] + h[5][0]);
  *reinterpret_cast<V2*>(m + 28) = V2{0.5 * (h[4][0] + h[4][0]), m45};
  *reinterpret_cast<V2*>(m + 34) = V2{m45, 0.5 * (h[5][1] + h[5][1])};
}

/// Over i, ((u0(i) v0 + u1(i) v1) + u2(i) v2): 3-vectors in a V4's first three lanes.
/// (Returned through x: a V4 returned by value is an ABI of its own with and without AVX.)
[[gnu::always_inline]] inline void sum3(V4& x, const V4& u0, const V4& u1, const V4& u2, double v0, double v1,
                                        double v2) {
  x = (u0 * V4{v0, v0, v0, v0} + u1 * V4{v1, v1, v1, v1}) + u2 * V4{v2, v2, v2, v2};
}

/// As sum3, but lane 2 summed as (u0(2) v0 + (u1(2) v1 + u2(2) v2)): Eigen's 3 x 3 product whose
/// left side is column-major takes rows 0 and 1 as one packet, in order, and row 2 alone, by
/// halves.
[[gnu::always_inline]] inline void sum3Rows(V4& x, const V4& u0, const V4& u1, const V4& u2, double v0,
                                            double v1, double v2) {
  const V4 p0 = u0 * V4{v0, v0, v0, v0}, p1 = u1 * V4{v1, v1, v1, v1}, p2 = u2 * V4{v2, v2, v2, v2};
  const V4 first = (p0 + p1) + p2, halves = p0 + (p1 + p2);
  x = V4{first[0], first[1], halves[2], 0};
}

/// The inverse of a symmetric 3 x 3 by cofactors, from its lower triangle (m00, m10, m20, m11,
/// m21, m22) as node_eigen::symmetricInverse3 takes it: its columns in c (lanes 0-2).
[[gnu::always_inline]] inline void inverse3(V4* c, double m00, double m10, double m20, double m11, double m21,
                                            double m22) {
  const double c00 = m11 * m22 - m21 * m21, c01 = m20 * m21 - m10 * m22, c02 = m10 * m21 - m20 * m11;
  const double c11 = m00 * m22 - m20 * m20, c12 = m10 * m20 - m00 * m21, c22 = m00 * m11 - m10 * m10;
  const double inv = 1.0 / (m00 * c00 + m10 * c01 + m20 * c02);
  const V4 s = {inv, inv, inv, inv};
  c[0] = V4{c00, c01, c02, 0} * s;
  c[1] = V4{c01, c11, c12, 0} * s;
  c[2] = V4{c02, c12, c22, 0} * s;
}

/// node_eigen::invertSymmetric (which says how) on a column-major 6 x 6, in place: each 3 x 3
/// product's elements summed in Eigen's order there (sum3Rows; q^T x's all in order, as Eigen's
/// dot products of two columns).
[[gnu::always_inline]] inline void invertSymmetric(double* a) {
  // The 3 x 3 blocks' columns in memory, 4 doubles each (lane 3 unused), read back one element
  // at a time as the products' factors.
  alignas(32) double pi[12], x[12], si[12], y[12];
  auto col = [](double* m, int j) -> V4& { return *reinterpret_cast<V4*>(m + 4 * j); };
  inverse3(&col(pi, 0), a[0], a[1], a[2], a[7], a[8], a[14]);
  // x = pi q, q = the top right block: q(k, j) = a[k + 6 (3 + j)].
  for (int j = 0; j < 3; ++j)
    sum3Rows(col(x, j), col(pi, 0), col(pi, 1), col(pi, 2), a[18 + 6 * j], a[19 + 6 * j], a[20 + 6 * j]);
  // S = R - q^T x (its lower triangle), R the bottom right block.
  auto qx = [&](int i, int j) {
    return (a[18 + 6 * i] * x[4 * j] + a[19 + 6 * i] * x[4 * j + 1]) + a[20 + 6 * i] * x[4 * j + 2];
  };
  inverse3(&col(si, 0), a[21] - qx(0, 0), a[22] - qx(1, 0), a[23] - qx(2, 0), a[28] - qx(1, 1),
           a[29] - qx(2, 1), a[35] - qx(2, 2));
  for (int j = 0; j < 3; ++j)
    sum3Rows(col(y, j), col(x, 0), col(x, 1), col(x, 2), si[4 * j], si[4 * j + 1], si[4 * j + 2]);
  for (int c = 0; c < 3; ++c) {
    V4 yx;  // (y x^T) column c: sum over k of y's column k times x(c, k)
    sum3Rows(yx, col(y, 0), col(y, 1), col(y, 2), x[c], x[4 + c], x[8 + c]);
    const V4 tl = col(pi, c) + yx;
    *reinterpret_cast<V4*>(a + 6 * c) = V4{tl[0], tl[1], tl[2], -y[c]};
    *reinterpret_cast<V2*>(a + 6 * c + 4) = V2{-y[4 + c], -y[8 + c]};
    *reinterpret_cast<V4*>(a + 18 + 6 * c) = V4{-y[4 * c], -y[4 * c + 1], -y[4 * c + 2], si[4 * c]};
    *reinterpret_cast<V2*>(a + 22 + 6 * c) = V2{si[4 * c + 1], si[4 * c + 2]};
  }
}

/// node_eigen::passShare (which says what the products mean) on column-major 6 x 6 arrays: pd
/// -= H^T G, with G = D^-1 H made first where `fresh`, then pd made exactly symmetric. Each
/// element takes the operations of Eigen's evaluation of that function's expressions, in their
/// order: a 6-row column's products summed column by column, and a 3-row block's (Eigen takes
/// them element by element, each a dot product of two columns) as ((p0 + p1) + p2).
[[gnu::always_inline]] inline void passShare(double* pd, double* g, const double* d, const double* jac,
                                             bool joint, bool axial, bool fresh) {
  const double s = jac[0];
  // a = jac's top right 3 x 3, b its bottom right: a(k, j) = jac[k + 6 (3 + j)]. Without the axial
  // row, b's row 2 is zeroed, not left out (its products by +0 give the same signed zeros).
  const double* a = jac + 18;
  const double* b = jac + 21;
  auto bk = [&](int k, int j) { return k == 2 && !axial ? 0.0 : b[k + 6 * j]; };
  if (joint) {
    if (fresh) {
      for (int k = 0; k < 3; ++k) store(g + 6 * k, column(d, k, s));
      for (int j = 0; j < 3; ++j) {
        const Col6 l = (column(d, 0, a[6 * j]) + column(d, 1, a[1 + 6 * j])) + column(d, 2, a[2 + 6 * j]);
        const Col6 r = (column(d, 3, bk(0, j)) + column(d, 4, bk(1, j))) + column(d, 5, bk(2, j));
        store(g + 6 * (3 + j), l + r);
      }
    }
    // Rows of a and b as 3-vectors over their columns: (a^T g)(i, c) = sum_k a(k, i) g(k, c).
    V4 ar[3], br[3];
    for (int k = 0; k < 3; ++k) {
      ar[k] = V4{a[k], a[k + 6], a[k + 12], 0};
      br[k] = V4{bk(k, 0), bk(k, 1), bk(k, 2), 0};
    }
    for (int c = 0; c < 6; ++c) {
      const double* gc = g + 6 * c;
      V4 xa, xb;
      sum3(xa, ar[0], ar[1], ar[2], gc[0], gc[1], gc[2]);
      sum3(xb, br[0], br[1], br[2], gc[3], gc[4], gc[5]);
      const V4 x = xa + xb;
      const V4 top = *reinterpret_cast<const V4*>(gc) * V4{s, s, s, s};
      const V4 lo = {top[0], top[1], top[2], x[0]};
      const V2 hi = {x[1], x[2]};
      subtract(pd + 6 * c, Col6{lo, hi});
    }
  } else {
    if (fresh) {
      for (int k = 0; k < 3; ++k) {
        store(g + 6 * k,
              column(d, k, s) + ((column(d, 3, a[k]) + column(d, 4, a[k + 6])) + column(d, 5, a[k + 12])));
        store(g + 6 * (3 + k), (column(d, 3, bk(k, 0)) + column(d, 4, bk(k, 1))) + column(d, 5, bk(k, 2)));
      }
    }
    // Columns of a and b as 3-vectors: (a g_bottom)(i, c) = sum_m a(i, m) g(3 + m, c).
    V4 ac[3], bc[3];
    for (int m = 0; m < 3; ++m) {
      ac[m] = V4{a[6 * m], a[1 + 6 * m], a[2 + 6 * m], 0};
      bc[m] = V4{bk(0, m), bk(1, m), bk(2, m), 0};
    }
    for (int c = 0; c < 6; ++c) {
      const double* gc = g + 6 * c;
      V4 t, x;
      sum3(t, ac[0], ac[1], ac[2], gc[3], gc[4], gc[5]);
      t = *reinterpret_cast<const V4*>(gc) * V4{s, s, s, s} + t;
      sum3(x, bc[0], bc[1], bc[2], gc[3], gc[4], gc[5]);
      const V4 lo = {t[0], t[1], t[2], x[0]};
      const V2 hi = {x[1], x[2]};
      subtract(pd + 6 * c, Col6{lo, hi});
    }
  }
  symmetrise(pd);
}

/// J's right half times w, [A w; B w] for J = [sI A; 0 B] (6 x 6, column-major) and w in lanes
/// 0-2, as Eigen's 3 x 3 products take each block: rows 0 and 1 of each summed in order, row 2 by
/// halves (sum3Rows).
[[gnu::always_inline]] inline Col6 rightHalf(const double* j, const V4& w) {
  const Col6 p0 = column(j, 3, w[0]), p1 = column(j, 4, w[1]), p2 = column(j, 5, w[2]);
  const V4 first = (p0.lo + p1.lo) + p2.lo, halves = p0.lo + (p1.lo + p2.lo);
  const V2 firstHi = (p0.hi + p1.hi) + p2.hi, halvesHi = p0.hi + (p1.hi + p2.hi);
  return {V4{first[0], first[1], halves[2], first[3]}, V2{firstHi[0], halvesHi[1]}};
}

/// node_eigen::jointResidual on column-major arrays: y = -bias - J_a v_a - J_b v_b, ja (jb) null
/// without body a (b); each body's linear and angular velocity in lanes 0-2 of two vectors.
/// (Where an element has nothing to add, -0 is added and +0 taken away: the same bits, signed
/// zeros too.)
[[gnu::always_inline]] inline void jointResidual(double* y, const double* bias, const double* ja,
                                                 const V4& linA, const V4& angA, const double* jb,
                                                 const V4& linB, const V4& angB) {
  V4 lo = -*reinterpret_cast<const V4*>(bias);
  V2 hi = -*reinterpret_cast<const V2*>(bias + 4);
  if (ja) {
    const Col6 jw = rightHalf(ja, angA);
    lo -= V4{linA[0], linA[1], linA[2], -0.0} + jw.lo;
    hi -= jw.hi;
  }
  if (jb) {
    const Col6 jw = rightHalf(jb, angB);
    lo -= jw.lo - V4{linB[0], linB[1], linB[2], 0.0};
    hi -= jw.hi;
  }
  *reinterpret_cast<V4*>(y) = lo;
  *reinterpret_cast<V2*>(y + 4) = hi;
}

/// How many nodes ahead of the one it works on a pass calls ahead(k): about a memory latency.
constexpr int kAhead = 8;

/// Node k's step of the down pass below: x = D^-1 y and, but for a parent `skip`, the parent's
/// y -= G^T y (prepare as there).
template <class Node, class Prepare>
[[gnu::always_inline]] inline void downStep(Node* nodes, int k, int skip, const Prepare& prepare) {
  Node& n = nodes[k];
  prepare(k);
  store(n.x.data(), product(n.dinv.data(), n.y.data()));
  if (n.parent >= 0 && n.parent != skip) {
    prepare(n.parent);
    subtract(nodes[n.parent].y.data(), transposedProduct(n.g.data(), n.y.data()));
  }
}

/// The down pass over nodes[order[i]] (nodes[i] where order is null), i from to - 1 down to from:
/// x = D^-1 y and, but for a parent `skip`, the parent's y -= G^T y. Node: dinv, g, y and x (Eigen
/// 6 x 6 and 6 x 1, column-major) and parent. prepare(k) is called before node k's
/// y is first read or written (each time: it may make y there, once); ahead(k) kAhead nodes
/// before node k's turn (to fetch what prepare will read).
template <class Node, class Prepare, class Ahead>
[[gnu::always_inline]] inline void downPass(Node* nodes, int from, int to, const int* order, int skip,
                                            const Prepare& prepare, const Ahead& ahead) {
  for (int i = to - 1; i >= from; --i) {
    if (i - kAhead >= from) ahead(order ? order[i - kAhead] : i - kAhead);
    downStep(nodes, order ? order[i] : i, skip, prepare);
  }
}

/// The up pass over the same nodes, first to last: x -= G x_parent; then finish(k), x final;
/// ahead(k) kAhead nodes before node k's turn.
template <class Node, class Finish, class Ahead>
[[gnu::always_inline]] inline void upPass(Node* nodes, int from, int to, const int* order,
                                          const Finish& finish, const Ahead& ahead) {
  for (int i = from; i < to; ++i) {
    if (i + kAhead < to) ahead(order ? order[i + kAhead] : i + kAhead);
    const int k = order ? order[i] : i;
    Node& n = nodes[k];
    if (n.parent >= 0) subtract(n.x.data(), product(n.g.data(), nodes[n.parent].x.data()));
    finish(k);
  }
}

}  // namespace rm3d::node_products
