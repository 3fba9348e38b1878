// The exact solver's steps node by node, in Eigen: a node's pivot block inverted and its share
// passed to its parent's (the factor), and a hinge's rows' velocity (each iteration's right-hand
// side). ExactSolver runs these where the CPU has no AVX; node_products.h has the same steps on
// AVX, which must give these functions' bits (tests/engine/physics/node_products_test.cpp).
#pragma once

#include <Eigen/Core>

namespace rm3d::node_eigen {

using Mat6 = Eigen::Matrix<double, 6, 6>;
using Mat3d = Eigen::Matrix3d;
using Vec6 = Eigen::Matrix<double, 6, 1>;

/// Inverse of a symmetric 3x3 matrix by cofactors (its lower triangle read).
inline Mat3d symmetricInverse3(const Mat3d& m) {
  const double a = m(0, 0), b = m(1, 0), c = m(2, 0), d = m(1, 1), e = m(2, 1), f = m(2, 2);
  const double c00 = d * f - e * e, c01 = c * e - b * f, c02 = b * e - c * d;
  const double c11 = a * f - c * c, c12 = b * c - a * e, c22 = a * d - b * b;
  const double inv = 1.0 / (a * c00 + b * c01 + c * c02);
  Mat3d r;
  r << c00 * inv, c01 * inv, c02 * inv, c01 * inv, c11 * inv, c12 * inv, c02 * inv, c12 * inv, c22 * inv;
  return r;
}

/// Inverse of a symmetric, definite (positive or negative) 6x6 matrix [P Q; Q^T R] by its 3x3
/// blocks: P and the Schur complement S = R - Q^T P^-1 Q are definite too, so no pivoting, and
/// two 3x3 inverses by cofactors cost less than half of a 6x6 LDL^T (40 ns against 90 here, the
/// same rounding error).
///
/// In place: every element is read before the first is written (a returned matrix cost a 288-byte
/// copy, half of the factor's own time outside its products).
inline void invertSymmetric(Mat6& a) {
  const Mat3d pi = symmetricInverse3(a.topLeftCorner<3, 3>());
  const Mat3d q = a.topRightCorner<3, 3>();
  const Mat3d x = pi * q;
  const Mat3d si = symmetricInverse3(a.bottomRightCorner<3, 3>() - q.transpose() * x);
  const Mat3d y = x * si;
  a.topLeftCorner<3, 3>() = pi + y * x.transpose();
  a.topRightCorner<3, 3>() = -y;
  a.bottomLeftCorner<3, 3>() = -y.transpose();
  a.bottomRightCorner<3, 3>() = si;
}

/// D_i = H_ii - sum over children H_ci^T D_c^-1 H_ci: a node's share of its parent's pivot pd
/// (after its own pivot d is inverted), with G = D^-1 H made first where `fresh` (else the last
/// factor's).
///
/// H(node, parent) is a hinge's rows on one body (a joint node, `joint`), J = [sI A; 0 B] (s =
/// +-1: the pivot rows' sign; A the pivot arm's cross product; B the axes), or its transpose (a
/// body node), without the axial row (row 5) unless `axial`: the products go by 3x3 blocks,
/// without the zero block and with sI as a sign (half of the dense products' multiplications).
inline void passShare(Mat6& pd, Mat6& g, const Mat6& d, const Mat6& jac, bool joint, bool axial, bool fresh) {
  const double s = jac(0, 0);
  const auto a = jac.topRightCorner<3, 3>();
  Mat3d b = jac.bottomRightCorner<3, 3>();
  if (!axial) b.row(2).setZero();
  const auto dl = d.leftCols<3>();
  const auto dr = d.rightCols<3>();
  if (joint) {
    // H = J: G = [s Dl, Dl A + Dr B]; H^T G = [s G_top; A^T G_top + B^T G_bottom].
    if (fresh) {
      g.leftCols<3>() = s * dl;
      g.rightCols<3>() = dl.lazyProduct(a) + dr.lazyProduct(b);
    }
    pd.topRows<3>() -= s * g.topRows<3>();
    pd.bottomRows<3>() -=
        a.transpose().lazyProduct(g.topRows<3>()) + b.transpose().lazyProduct(g.bottomRows<3>());
  } else {
    // H = J^T = [sI 0; A^T B^T]: G = [s Dl + Dr A^T, Dr B^T]; H^T G = [s G_top + A G_bottom; B G_bottom].
    const Mat3d at = a.transpose(), bt = b.transpose();
    if (fresh) {
      g.leftCols<3>() = s * dl + dr.lazyProduct(at);
      g.rightCols<3>() = dr.lazyProduct(bt);
    }
    pd.topRows<3>() -= s * g.topRows<3>() + at.transpose().lazyProduct(g.bottomRows<3>());
    pd.bottomRows<3>() -= bt.transpose().lazyProduct(g.bottomRows<3>());
  }
  // Kept exactly symmetric: each pair of elements set to their mean, in place (the same bits as
  // 0.5 (D + D^T) without the temporary; the diagonal too, which a flushed denormal would change).
  for (int col = 0; col < 6; ++col)
    for (int row = col; row < 6; ++row) pd(row, col) = pd(col, row) = 0.5 * (pd(row, col) + pd(col, row));
}

/// A hinge's structural residual -bias - J v: J = [sI A; 0 B] on each body (jointRows), J v =
/// [s v + A w; B w] with s = 1 on body a and -1 on body b; ja (jb) null where the row has no body
/// a (b) in the tree.
inline Vec6 jointResidual(const Vec6& bias, const Mat6* ja, const Vec6& va, const Mat6* jb, const Vec6& vb) {
  Vec6 y = -bias;
  if (ja) {
    y.head<3>() -= va.head<3>() + ja->topRightCorner<3, 3>().lazyProduct(va.tail<3>());
    y.tail<3>() -= ja->bottomRightCorner<3, 3>().lazyProduct(va.tail<3>());
  }
  if (jb) {
    y.head<3>() -= jb->topRightCorner<3, 3>().lazyProduct(vb.tail<3>()) - vb.head<3>();
    y.tail<3>() -= jb->bottomRightCorner<3, 3>().lazyProduct(vb.tail<3>());
  }
  return y;
}

}  // namespace rm3d::node_eigen
