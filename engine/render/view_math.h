// Camera matrices shared by the renderer and by picking, so a ray cast from a pixel goes through
// exactly what the renderer drew there. Plain Eigen: no GL here.
#pragma once

#include <Eigen/Geometry>

#include "io/snapshot.h"

namespace rm3d {

constexpr float kNearPlane = 0.01f, kFarPlane = 100.0f;

/// World -> eye (OpenGL convention: the eye looks down -z).
Eigen::Matrix4f lookAt(const Eigen::Vector3f& eye, const Eigen::Vector3f& target, Eigen::Vector3f up);
/// Eye -> clip, OpenGL depth range [-1, 1].
Eigen::Matrix4f perspective(float fovyDeg, float aspect, float nearPlane, float farPlane);
/// World -> clip for cam on a view of the given aspect (width / height).
Eigen::Matrix4f viewProjection(const Camera& cam, float aspect);

struct Ray {
  Eigen::Vector3f origin;
  Eigen::Vector3f dir;  ///< unit
};

/// The ray from the eye through pixel position (x, y) of a width x height view (origin top-left,
/// pixel centres at +0.5).
Ray pixelRay(const Camera& cam, int width, int height, float x, float y);

}  // namespace rm3d
