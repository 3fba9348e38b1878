// Conversions between Bullet's single-precision vectors and Eigen's doubles, for the solver's own
// rows (contact_patches.cpp, capture_joint.cpp).
#pragma once

#include <LinearMath/btQuaternion.h>
#include <LinearMath/btVector3.h>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>

namespace rm3d::bt {

inline Eigen::Vector3d toEigen(const btVector3& v) {
  return {double(v.x()), double(v.y()), double(v.z())};
}

inline btVector3 toBt(const Eigen::Vector3d& v) {
  return {btScalar(v.x()), btScalar(v.y()), btScalar(v.z())};
}

/// A unit quaternion in doubles (Bullet's are floats: normalised again).
inline Eigen::Quaterniond toEigen(const btQuaternion& q) {
  return Eigen::Quaterniond(double(q.w()), double(q.x()), double(q.y()), double(q.z())).normalized();
}

/// The rotation vector (axis times angle) of q, taking the short way round.
inline Eigen::Vector3d rotationVector(Eigen::Quaterniond q) {
  if (q.w() < 0) q.coeffs() = -q.coeffs();
  const double s = q.vec().norm();
  if (s < 1e-12) return 2 * q.vec();
  return q.vec() * (2 * std::atan2(s, q.w()) / s);
}

}  // namespace rm3d::bt
