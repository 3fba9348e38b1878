// Dock frames and mating: normals opposite, orientations 360/symmetry apart, gender rules.
#include "docking/dock_frame.h"

#include <doctest/doctest.h>

using namespace rm3d;

TEST_CASE("the mating frame faces the dock and turns by orientation * 360/symmetry") {
  DockDef d;
  d.pos = Vec3(0.1, 0.2, 0.3);
  d.normal = Vec3(0, 1, 0);
  d.up = Vec3(0, 0, 1);
  const Pose a = dockFrame(d);
  CHECK((a.rot * Vec3::UnitX() - d.normal).norm() < 1e-12);
  CHECK((a.rot * Vec3::UnitZ() - d.up).norm() < 1e-12);
  for (int k = 0; k < 4; ++k) {
    const Pose b = matingFrame(a, k, 4);
    CHECK((b.pos - a.pos).norm() < 1e-12);
    CHECK(dockError(a, b).angle < 1e-9);
    const double turn = std::atan2((a.rot * Vec3::UnitZ()).cross(b.rot * Vec3::UnitZ()).dot(d.normal),
                                   (a.rot * Vec3::UnitZ()).dot(b.rot * Vec3::UnitZ()));
    CHECK(std::abs(std::remainder(turn - k * kPi / 2, 2 * kPi)) < 1e-9);
  }
}

TEST_CASE("genders: male-female and genderless-genderless mate, nothing else") {
  CHECK(gendersMate(Gender::Male, Gender::Female));
  CHECK(gendersMate(Gender::Female, Gender::Male));
  CHECK(gendersMate(Gender::None, Gender::None));
  CHECK_FALSE(gendersMate(Gender::Male, Gender::Male));
  CHECK_FALSE(gendersMate(Gender::Female, Gender::Female));
  CHECK_FALSE(gendersMate(Gender::None, Gender::Male));
}
