// Volume, centre of mass and inertia of the shape kinds, used to build link and body mass
// properties (hulls integrate their triangles as signed tetrahedra).
#include "physics/shape_def.h"

#include <algorithm>
#include <cmath>

namespace rm3d {

namespace {

MassProps hullMassProps(const ShapeDef& s) {
  MassProps mp;
  // Integrate over tetrahedra (origin, a, b, c); exact for a closed, consistently wound mesh.
  double vol = 0;
  Vec3 c = Vec3::Zero();
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();  // second moment about the origin
  for (size_t t = 0; t + 2 < s.triangles.size(); t += 3) {
    const Vec3& a = s.points[s.triangles[t]];
    const Vec3& b = s.points[s.triangles[t + 1]];
    const Vec3& d = s.points[s.triangles[t + 2]];
    const double v = a.dot(b.cross(d)) / 6.0;
    vol += v;
    c += v * (a + b + d) / 4.0;
    const Vec3 sum = a + b + d;
    cov += v / 20.0 * (a * a.transpose() + b * b.transpose() + d * d.transpose() + sum * sum.transpose());
  }
  if (vol <= 1e-12) {  // open or inverted mesh: fall back to its bounding box
    Vec3 lo = s.points.empty() ? Vec3::Zero() : s.points[0], hi = lo;
    for (const Vec3& p : s.points) {
      lo = lo.cwiseMin(p);
      hi = hi.cwiseMax(p);
    }
    const Vec3 e = (hi - lo).cwiseMax(1e-6);
    mp.volume = e.x() * e.y() * e.z();
    mp.com = (lo + hi) / 2;
    mp.inertia = Eigen::Vector3d(e.y() * e.y() + e.z() * e.z(), e.x() * e.x() + e.z() * e.z(),
                                 e.x() * e.x() + e.y() * e.y())
                     .asDiagonal();
    mp.inertia *= mp.volume / 12.0;
    return mp;
  }
  c /= vol;
  mp.volume = vol;
  mp.com = c;
  const Eigen::Matrix3d covCom = cov - vol * c * c.transpose();
  mp.inertia = Eigen::Matrix3d::Identity() * covCom.trace() - covCom;
  return mp;
}

}  // namespace

MassProps shapeMassProps(const ShapeDef& s) {
  if (s.massProps) return *s.massProps;
  MassProps mp;
  switch (s.kind) {
    case ShapeKind::Box: {
      const Vec3& e = s.size;
      mp.volume = e.x() * e.y() * e.z();
      mp.inertia = Eigen::Vector3d(e.y() * e.y() + e.z() * e.z(), e.x() * e.x() + e.z() * e.z(),
                                   e.x() * e.x() + e.y() * e.y())
                       .asDiagonal();
      mp.inertia *= mp.volume / 12.0;
      break;
    }
    case ShapeKind::Sphere: {
      const double r = s.radius;
      mp.volume = 4.0 / 3.0 * kPi * r * r * r;
      mp.inertia = Eigen::Matrix3d::Identity() * (0.4 * mp.volume * r * r);
      break;
    }
    case ShapeKind::Cylinder: {
      const double r = s.radius, h = s.length;
      mp.volume = kPi * r * r * h;
      const double ixy = mp.volume * (3 * r * r + h * h) / 12.0;
      mp.inertia = Eigen::Vector3d(ixy, ixy, mp.volume * r * r / 2.0).asDiagonal();
      break;
    }
    case ShapeKind::Capsule: {
      // A cylinder of length h plus two hemispheres (each 2/3 pi r^3, its centre of mass 3r/8
      // from the flat face), inertia about the capsule's centre.
      const double r = s.radius, h = s.length;
      const double vc = kPi * r * r * h, vh = 2.0 / 3.0 * kPi * r * r * r;
      mp.volume = vc + 2 * vh;
      const double ixy =
          vc * (3 * r * r + h * h) / 12.0 + 2 * vh * (2.0 * r * r / 5.0 + h * h / 4.0 + 3.0 * h * r / 8.0);
      const double iz = vc * r * r / 2.0 + 2 * vh * 2.0 * r * r / 5.0;
      mp.inertia = Eigen::Vector3d(ixy, ixy, iz).asDiagonal();
      break;
    }
    case ShapeKind::Hull:
      return hullMassProps(s);
    case ShapeKind::TriMesh:
    case ShapeKind::Heightfield:
      break;  // static only: no mass
  }
  return mp;
}

double HeightGrid::heightAt(double x, double y) const {
  if (nx < 2 || ny < 2 || heights.size() != size_t(nx) * size_t(ny)) return 0;
  const double fx = std::clamp((x + sx / 2) / cellX(), 0.0, double(nx - 1));
  const double fy = std::clamp((y + sy / 2) / cellY(), 0.0, double(ny - 1));
  const int i = std::min(int(fx), nx - 2), j = std::min(int(fy), ny - 2);
  const double u = fx - i, v = fy - j;
  const double h00 = at(i, j), h10 = at(i + 1, j), h01 = at(i, j + 1), h11 = at(i + 1, j + 1);
  // The cell's two triangles share the diagonal (i+1, j)-(i, j+1).
  if (u + v <= 1) return h00 + u * (h10 - h00) + v * (h01 - h00);
  return h11 + (1 - u) * (h01 - h11) + (1 - v) * (h10 - h11);
}

// The same sums as PhysicsWorld::addPart, which builds a part's body from its shapes.
MassProps compoundMassProps(const std::vector<ShapeDef>& shapes, double mass) {
  std::vector<MassProps> props;
  double fixedMass = 0, freeVolume = 0;
  for (const ShapeDef& s : shapes) {
    props.push_back(shapeMassProps(s));
    if (s.mass >= 0)
      fixedMass += s.mass;
    else
      freeVolume += props.back().volume;
  }
  std::vector<double> masses;
  double total = 0;
  MassProps out;
  for (size_t i = 0; i < shapes.size(); ++i) {
    const double mi = shapes[i].mass >= 0
                          ? shapes[i].mass
                          : (freeVolume > 0 ? (mass - fixedMass) * props[i].volume / freeVolume : 0);
    masses.push_back(std::max(mi, 0.0));
    total += masses.back();
    out.volume += props[i].volume;
  }
  if (mass <= 0 || total <= 0) return out;
  Vec3 com = Vec3::Zero();
  for (size_t i = 0; i < shapes.size(); ++i) com += masses[i] * (shapes[i].pose * props[i].com);
  com /= total;
  Eigen::Matrix3d inertia = Eigen::Matrix3d::Zero();
  for (size_t i = 0; i < shapes.size(); ++i) {
    const double density = props[i].volume > 0 ? masses[i] / props[i].volume : 0;
    const Eigen::Matrix3d r = shapes[i].pose.rot.toRotationMatrix();
    const Vec3 d = shapes[i].pose * props[i].com - com;
    inertia += density * r * props[i].inertia * r.transpose() +
               masses[i] * (d.squaredNorm() * Eigen::Matrix3d::Identity() - d * d.transpose());
  }
  out.com = com;
  out.inertia = inertia * (mass / total);
  return out;
}

std::vector<ShapeDef> massFrom(const std::vector<ShapeDef>& visual, std::vector<ShapeDef> collision,
                               double mass) {
  if (collision.empty() || mass <= 0) return collision;
  const MassProps whole = compoundMassProps(visual, mass);
  for (ShapeDef& s : collision) {
    s.mass = 0;
    s.massProps.reset();
  }
  // The first shape holds the whole mass at unit volume (density = mass), its centre of mass and
  // inertia expressed in the shape's own frame.
  ShapeDef& first = collision.front();
  const Eigen::Matrix3d r = first.pose.rot.toRotationMatrix();
  MassProps carried;
  carried.volume = 1;
  carried.com = first.pose.inverse() * whole.com;
  carried.inertia = r.transpose() * whole.inertia * r / mass;
  first.mass = mass;
  first.massProps = carried;
  return collision;
}

}  // namespace rm3d
