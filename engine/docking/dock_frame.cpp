// Dock frame construction and face-to-face mating.
#include "docking/dock_frame.h"

namespace rm3d {

Pose dockFrame(const DockDef& d) {
  const Vec3 x = d.normal.normalized();
  const Vec3 z = (d.up - d.up.dot(x) * x).normalized();
  Eigen::Matrix3d r;
  r.col(0) = x;
  r.col(1) = z.cross(x);
  r.col(2) = z;
  return {d.pos, Quat(r).normalized()};
}

Pose matingFrame(const Pose& a, int orientation, int symmetry) {
  const int sym = symmetry > 0 ? symmetry : 1;
  const double theta = 2.0 * kPi * double(((orientation % sym) + sym) % sym) / double(sym);
  const Quat flip(Eigen::AngleAxisd(kPi, Vec3::UnitZ()));
  const Quat turn(Eigen::AngleAxisd(theta, Vec3::UnitX()));
  return {a.pos, (a.rot * turn * flip).normalized()};
}

DockError dockError(const Pose& a, const Pose& b) {
  DockError e;
  e.gap = (a.pos - b.pos).norm();
  e.angle = angleBetween(a.rot * Vec3::UnitX(), -(b.rot * Vec3::UnitX()));
  return e;
}

bool gendersMate(Gender a, Gender b) {
  if (a == Gender::None || b == Gender::None) return a == b;
  return a != b;
}

}  // namespace rm3d
