// The automatic camera (sceneCamera) frames particle sets as it frames bodies: from their bounds
// at the start, so particles moving later widen nothing.
#include <doctest/doctest.h>

#include "io/scene_state.h"

TEST_CASE("sceneCamera frames the particle sets' bounds at the start") {
  rm3d::SceneLayout layout;  // no modules, no bodies: the default frame about the origin
  rm3d::SceneState start;
  const rm3d::Camera bare = rm3d::sceneCamera(layout, start, start);
  CHECK(bare.target.isApprox(Eigen::Vector3f(0, 0, 0.1f)));

  start.particleBounds.emplace_back(rm3d::Vec3(2, 2, 0), rm3d::Vec3(4, 4, 1));
  start.particleBounds.emplace_back();  // an empty set: no bounds, not framed
  const rm3d::Camera cam = rm3d::sceneCamera(layout, start, start);
  CHECK(cam.target.isApprox(Eigen::Vector3f(3, 3, 0.5f)));
  // Far enough back for the whole pool: 0.9 of its diagonal and a margin.
  CHECK((cam.eye - cam.target).norm() == doctest::Approx(0.9 * (std::sqrt(9.0) + 0.3)).epsilon(1e-4));

  // Particles elsewhere now (splashed far away) leave the start's frame as it was.
  rm3d::SceneState now = start;
  now.particleBounds[0] = Eigen::AlignedBox3d(rm3d::Vec3(-9, -9, 0), rm3d::Vec3(-8, -8, 1));
  const rm3d::Camera later = rm3d::sceneCamera(layout, start, now);
  CHECK(later.eye.isApprox(cam.eye));
  CHECK(later.target.isApprox(cam.target));
}
