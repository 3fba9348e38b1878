// The exact solver's tree solve, node by node: the three products of its 6 x 6 blocks, four rows
// at a time. Each element takes the same operations in the same order as Eigen's fixed-size
// products (coefficient-based, no fused multiply-add), so the result is the same, bit for bit,
// compiled for SSE2 or AVX: ExactSolver runs the AVX build where the CPU has it.
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

/// m^T v given mt = m^T column-major (its columns are m's rows), as Eigen's `m.transpose() * v`:
/// each element a dot product taken in pairs, (t0 + (t2 + t4)) + (t1 + (t3 + t5)).
[[gnu::always_inline]] inline Col6 transposedProduct(const double* mt, const double* v) {
  return (column(mt, 0, v[0]) + (column(mt, 2, v[2]) + column(mt, 4, v[4]))) +
         (column(mt, 1, v[1]) + (column(mt, 3, v[3]) + column(mt, 5, v[5])));
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

/// The down pass over nodes[order[i]] (nodes[i] where order is null), i from to - 1 down to from:
/// x = D^-1 y and, but for a parent `skip`, the parent's y -= G^T y. Node: dinv, g's transpose gt,
/// y and x (Eigen 6 x 6 and 6 x 1, column-major) and parent. prepare(k) is called before node k's
/// y is first read or written (each time: it may make y there, once).
template <class Node, class Prepare>
[[gnu::always_inline]] inline void downPass(Node* nodes, int from, int to, const int* order, int skip,
                                            const Prepare& prepare) {
  for (int i = to - 1; i >= from; --i) {
    const int k = order ? order[i] : i;
    Node& n = nodes[k];
    prepare(k);
    store(n.x.data(), product(n.dinv.data(), n.y.data()));
    if (n.parent >= 0 && n.parent != skip) {
      prepare(n.parent);
      subtract(nodes[n.parent].y.data(), transposedProduct(n.gt.data(), n.y.data()));
    }
  }
}

/// The up pass over the same nodes, first to last: x -= G x_parent; then finish(k), x final.
template <class Node, class Finish>
[[gnu::always_inline]] inline void upPass(Node* nodes, int from, int to, const int* order,
                                          const Finish& finish) {
  for (int i = from; i < to; ++i) {
    const int k = order ? order[i] : i;
    Node& n = nodes[k];
    if (n.parent >= 0) subtract(n.x.data(), product(n.g.data(), nodes[n.parent].x.data()));
    finish(k);
  }
}

}  // namespace rm3d::node_products
