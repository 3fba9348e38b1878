// Math vocabulary shared by every subsystem: Eigen vectors, quaternions and rigid poses.
// Frames: right-handed, z up, SI units (metres, radians, seconds).
#pragma once

#include <Eigen/Geometry>

namespace rm3d {

using Vec3 = Eigen::Vector3d;
using Quat = Eigen::Quaterniond;

/// A rigid transform: maps points of a child frame into its parent frame (p' = q * p + pos).
struct Pose {
  Vec3 pos = Vec3::Zero();
  Quat rot = Quat::Identity();

  Vec3 operator*(const Vec3& p) const { return rot * p + pos; }
  Pose operator*(const Pose& o) const { return {rot * o.pos + pos, (rot * o.rot).normalized()}; }
  Pose inverse() const {
    Quat qi = rot.conjugate();
    return {qi * -pos, qi};
  }
};

/// Roll, pitch, yaw (radians, applied about fixed x, then y, then z) to a quaternion.
inline Quat quatFromRpy(double roll, double pitch, double yaw) {
  return (Eigen::AngleAxisd(yaw, Vec3::UnitZ()) * Eigen::AngleAxisd(pitch, Vec3::UnitY()) *
          Eigen::AngleAxisd(roll, Vec3::UnitX()))
      .normalized();
}

/// Angle between two unit vectors, radians, robust near 0 and pi.
inline double angleBetween(const Vec3& a, const Vec3& b) {
  return std::atan2(a.cross(b).norm(), a.dot(b));
}

constexpr double kPi = 3.14159265358979323846;
constexpr double kDegPerRad = 180.0 / kPi;

}  // namespace rm3d
