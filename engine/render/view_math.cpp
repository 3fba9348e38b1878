// Camera matrices and pixel rays (see view_math.h).
#include "render/view_math.h"

#include <cmath>

namespace rm3d {

Eigen::Matrix4f lookAt(const Eigen::Vector3f& eye, const Eigen::Vector3f& target, Eigen::Vector3f up) {
  Eigen::Vector3f f = (target - eye).normalized();
  if (f.cross(up).norm() < 1e-6f)
    up = std::abs(f.z()) < 0.9f ? Eigen::Vector3f::UnitZ() : Eigen::Vector3f::UnitY();
  Eigen::Vector3f s = f.cross(up).normalized(), u = s.cross(f);
  Eigen::Matrix4f m = Eigen::Matrix4f::Identity();
  m.block<1, 3>(0, 0) = s.transpose();
  m.block<1, 3>(1, 0) = u.transpose();
  m.block<1, 3>(2, 0) = -f.transpose();
  m(0, 3) = -s.dot(eye);
  m(1, 3) = -u.dot(eye);
  m(2, 3) = f.dot(eye);
  return m;
}

Eigen::Matrix4f perspective(float fovyDeg, float aspect, float n, float f) {
  const float t = 1.0f / std::tan(fovyDeg * 3.14159265f / 360.0f);
  Eigen::Matrix4f m = Eigen::Matrix4f::Zero();
  m(0, 0) = t / aspect;
  m(1, 1) = t;
  m(2, 2) = (f + n) / (n - f);
  m(2, 3) = 2.0f * f * n / (n - f);
  m(3, 2) = -1.0f;
  return m;
}

Eigen::Matrix4f viewProjection(const Camera& cam, float aspect) {
  return perspective(cam.fovyDeg, aspect, kNearPlane, kFarPlane) * lookAt(cam.eye, cam.target, cam.up);
}

Ray pixelRay(const Camera& cam, int width, int height, float x, float y) {
  // Unproject the pixel on the near and far planes through the very matrix the renderer uses.
  const Eigen::Matrix4f inv = viewProjection(cam, float(width) / float(height)).inverse();
  const float nx = 2.0f * x / float(width) - 1.0f, ny = 1.0f - 2.0f * y / float(height);
  const Eigen::Vector4f a = inv * Eigen::Vector4f(nx, ny, -1.0f, 1.0f);
  const Eigen::Vector4f b = inv * Eigen::Vector4f(nx, ny, 1.0f, 1.0f);
  const Eigen::Vector3f pa = a.head<3>() / a.w(), pb = b.head<3>() / b.w();
  return {pa, (pb - pa).normalized()};
}

}  // namespace rm3d
