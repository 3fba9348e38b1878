// Heightfields, capsules and concave meshes in PhysicsWorld: a ray straight down meets the
// heightfield at HeightGrid::heightAt (the same triangles), a capsule's mass properties, a body
// resting on a concave mesh's inside, and obstacles falling asleep.
#include <doctest/doctest.h>

#include <cmath>
#include <memory>

#include "physics/physics_world.h"

using namespace rm3d;

namespace {

void run(PhysicsWorld& w, double seconds) {
  for (int i = 0; i < int(seconds * 60); ++i) w.step(1.0 / 60, 4);
}

/// A 7 x 5 grid of rough heights over 3 x 2 m, up to 0.4 m.
std::shared_ptr<HeightGrid> roughGrid() {
  auto g = std::make_shared<HeightGrid>();
  g->nx = 7;
  g->ny = 5;
  g->sx = 3;
  g->sy = 2;
  g->maxHeight = 0.4;
  for (int j = 0; j < g->ny; ++j)
    for (int i = 0; i < g->nx; ++i)
      g->heights.push_back(float(0.2 + 0.2 * std::sin(1.7 * i + 0.3) * std::cos(2.3 * j + 1.1)));
  return g;
}

}  // namespace

TEST_CASE("a ray straight down meets the heightfield where HeightGrid::heightAt says") {
  PhysicsWorld w(PhysicsSettings{});
  ShapeDef s;
  s.kind = ShapeKind::Heightfield;
  s.grid = roughGrid();
  PartDesc d;
  d.shapes = {s};
  d.pose.pos = Vec3(0.5, -0.25, 0.1);  // centre of the grid in x, y; its base in z
  const int part = w.addPart(d);
  CHECK((w.partPose(part).pos - d.pose.pos).norm() < 1e-6);  // the part frame is the grid's, not Bullet's
  double worst = 0;
  for (int k = 0; k < 200; ++k) {
    // Points spread over the grid, including cell edges and diagonals.
    const double u = std::fmod(0.6180339887 * k, 1.0), v = std::fmod(0.4142135624 * k + 0.05, 1.0);
    const double x = -1.5 + 3 * u, y = -1 + 2 * v;
    const double hit = w.rayCast(Vec3(0.5 + x, -0.25 + y, 2), Vec3(0, 0, -1), 3, -1);
    REQUIRE(hit >= 0);
    const double z = 2 - hit, expected = 0.1 + s.grid->heightAt(x, y);
    worst = std::max(worst, std::abs(z - expected));
  }
  CHECK(worst < 1e-4);
}

TEST_CASE("a capsule's mass properties add a cylinder and two hemispheres") {
  ShapeDef c;
  c.kind = ShapeKind::Capsule;
  c.radius = 0.05;
  c.length = 0.2;
  const MassProps mp = shapeMassProps(c);
  const double vc = kPi * 0.05 * 0.05 * 0.2, vs = 4.0 / 3.0 * kPi * std::pow(0.05, 3);
  CHECK(mp.volume == doctest::Approx(vc + vs));
  // About the long axis: a cylinder's (v r^2 / 2) and a sphere's (2/5 v r^2).
  CHECK(mp.inertia(2, 2) == doctest::Approx(vc * 0.05 * 0.05 / 2 + 0.4 * vs * 0.05 * 0.05));
  CHECK(mp.inertia(0, 0) > mp.inertia(2, 2));
  CHECK(mp.inertia(0, 0) == doctest::Approx(mp.inertia(1, 1)));
}

TEST_CASE("a box rests inside a concave mesh, on its floor") {
  PhysicsWorld w(PhysicsSettings{});
  // A square tray: floor at z = 0 (2 triangles) and four walls 0.2 m high, open at the top.
  ShapeDef tray;
  tray.kind = ShapeKind::TriMesh;
  const double h = 0.5;
  tray.points = {{-h, -h, 0},   {h, -h, 0},   {h, h, 0},   {-h, h, 0},
                 {-h, -h, 0.2}, {h, -h, 0.2}, {h, h, 0.2}, {-h, h, 0.2}};
  tray.triangles = {0, 1, 2, 0, 2, 3, 0, 1, 5, 0, 5, 4, 1, 2, 6, 1, 6, 5, 2, 3, 7, 2, 7, 6, 3, 0, 4, 3, 4, 7};
  PartDesc t;
  t.shapes = {tray};
  w.addPart(t);
  ShapeDef cube;
  cube.size = Vec3(0.1, 0.1, 0.1);
  PartDesc b;
  b.shapes = {cube};
  b.mass = 0.5;
  b.pose.pos = Vec3(0.1, -0.1, 0.3);
  const int part = w.addPart(b);
  run(w, 2);
  CHECK(std::abs(w.partPose(part).pos.z() - 0.05) < 0.002);  // its convex hull would hold it at 0.25
  CHECK(std::abs(w.partPose(part).pos.x() - 0.1) < 0.01);    // a little skid on landing
}

TEST_CASE("still obstacles fall asleep; a module part never does; a push wakes one") {
  PhysicsWorld w(PhysicsSettings{});
  w.addGroundPlane(0.8, 0);
  ShapeDef cube;
  cube.size = Vec3(0.1, 0.1, 0.1);
  PartDesc b;
  b.shapes = {cube};
  b.mass = 0.5;
  b.pose.pos = Vec3(0, 0, 0.06);
  const int obstacle = w.addPart(b);
  b.pose.pos = Vec3(1, 0, 0.06);
  b.owner = 0;  // a module's link
  const int link = w.addPart(b);
  CHECK_FALSE(w.partSleeping(obstacle));
  run(w, 3);
  CHECK(w.partSleeping(obstacle));
  CHECK_FALSE(w.partSleeping(link));
  CHECK(w.activeBodyCount() == 1);
  w.setPartVelocity(obstacle, Vec3(0.5, 0, 0));
  CHECK_FALSE(w.partSleeping(obstacle));
  run(w, 0.1);
  CHECK(w.partPose(obstacle).pos.x() > 0.01);
}
