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
