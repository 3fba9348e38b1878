// Particles (engine/particles/particle_system.h): count conservation and a closed tank, the same
// state bit for bit with 1 and 2 threads (fluid and debris, coupled to a body), bodies that
// float or sink, and a pile of debris at a plausible angle of repose.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "test_world.h"

namespace {

using rm3d::World;

// A 0.4 x 0.4 m tank (walls 0.1 m thick and 0.4 m high) holding fluid 0.16 m deep, a box of
// density `box` kg/m^3 and edge 0.1 m dropped in, and a debris heap poured beside it.
std::string tank(double box, bool debris) {
  std::string s = R"(
world.set{duration = 100}
world.ground{}
local W, H, T = 0.4, 0.4, 0.1
world.box{size = {W + 2 * T, T, H}, at = {0, W / 2 + T / 2, H / 2}}
world.box{size = {W + 2 * T, T, H}, at = {0, -W / 2 - T / 2, H / 2}}
world.box{size = {T, W, H}, at = {W / 2 + T / 2, 0, H / 2}}
world.box{size = {T, W, H}, at = {-W / 2 - T / 2, 0, H / 2}}
world.fluid{min = {-W / 2, -W / 2, 0}, max = {W / 2, W / 2, 0.16}, spacing = 0.02}
)";
  s += "world.box{size = {0.1, 0.1, 0.1}, at = {0, 0, 0.3}, mass = " + std::to_string(box) + " * 0.001}\n";
  if (debris) s += "world.debris{min = {0.5, -0.05, 0}, max = {0.6, 0.05, 0.2}, spacing = 0.01}\n";
  return s;
}

/// The floating box is the last obstacle.
double boxZ(const World& w) {
  return w.obstaclePose(w.obstacles().back().part).pos.z();
}

}  // namespace

TEST_CASE("particles: a closed tank keeps every fluid particle, and the same run with 1 and 2 threads") {
  rm3d::RunOptions one = rm3d::test::options();
  rm3d::RunOptions two = one;
  two.threads = 2;
  auto a = rm3d::test::makeWorld(tank(500, true), one);
  auto b = rm3d::test::makeWorld(tank(500, true), two);
  const auto& fluid = *a->particleSystems()[0];
  const int n = fluid.count();
  CHECK(n == 20 * 20 * 8);
  for (int i = 0; i < 90; ++i) {
    a->step();
    b->step();
  }
  for (size_t k = 0; k < 2; ++k)
    CHECK(a->particleSystems()[k]->stateHash() == b->particleSystems()[k]->stateHash());
  CHECK(boxZ(*a) == boxZ(*b));
  CHECK(fluid.count() == n);
  CHECK(fluid.nanCount() == 0);
  // Every particle inside the tank: walls at +-0.2 m, radius 0.01 m.
  rm3d::Vec3 lo, hi;
  fluid.bounds(lo, hi);
  CHECK(lo.x() >= -0.2 + 0.009);
  CHECK(hi.x() <= 0.2 - 0.009);
  CHECK(lo.y() >= -0.2 + 0.009);
  CHECK(hi.y() <= 0.2 - 0.009);
  CHECK(lo.z() >= 0.0099);
  CHECK(hi.z() < 0.4);
}

TEST_CASE("particles: a box of half the fluid's density floats about half submerged; a dense one sinks") {
  auto light = rm3d::test::makeWorld(tank(500, false));
  auto heavy = rm3d::test::makeWorld(tank(2000, false));
  rm3d::test::stepFor(*light, 4);
  rm3d::test::stepFor(*heavy, 4);
  rm3d::Vec3 lo, hi;
  light->particleSystems()[0]->bounds(lo, hi);
  const double surface = hi.z() + light->particleSystems()[0]->radius();
  const double submerged = (surface - (boxZ(*light) - 0.05)) / 0.1;
  MESSAGE("surface " << surface << " m, box centre " << boxZ(*light) << " m, submerged " << submerged);
  CHECK(submerged > 0.35);
  CHECK(submerged < 0.75);
  MESSAGE("dense box centre " << boxZ(*heavy) << " m");
  CHECK(boxZ(*heavy) < 0.05 + 0.03);  // on the tank floor (under a particle layer at most)
}

/// Heap of debris poured as a 10 x 10 x 12 cm column, after 2 s: its height and the radius
/// holding 95 % of its bottom layer.
void heap(double friction, double& height, double& radius, double& speed) {
  auto w = rm3d::test::makeWorld(R"(
world.set{duration = 100}
world.ground{friction = 0.8}
world.debris{min = {-0.05, -0.05, 0}, max = {0.05, 0.05, 0.12}, spacing = 0.01, friction = )" +
                                 std::to_string(friction) + "}\n");
  rm3d::test::stepFor(*w, 2);
  const auto& d = *w->particleSystems()[0];
  CHECK(d.nanCount() == 0);
  CHECK(d.count() == 10 * 10 * 12);
  height = 0;
  std::vector<double> base;
  for (int i = 0; i < d.count(); ++i) {
    height = std::max(height, double(d.z()[size_t(i)]));
    if (d.z()[size_t(i)] < 0.015) base.push_back(std::hypot(d.x()[size_t(i)], d.y()[size_t(i)]));
  }
  std::sort(base.begin(), base.end());
  radius = base.empty() ? 0 : base[base.size() * 95 / 100];
  speed = d.meanVelocity().norm();
}

TEST_CASE("particles: debris friction holds a heap together and lets it settle") {
  // Grains without friction flow out like a fluid; with friction the heap stays several times
  // narrower and comes to rest. (A true angle of repose of 20-40 degrees is not reached yet: the
  // heap ends two grains high, README "Fluids and debris".)
  double h0, r0, v0, h1, r1, v1;
  heap(0.0, h0, r0, v0);
  heap(0.6, h1, r1, v1);
  MESSAGE("frictionless: " << h0 << " m high, " << r0 << " m wide; friction 0.6: " << h1 << " m high, " << r1
                           << " m wide, " << std::atan2(h1, r1) * 180 / 3.14159265358979 << " deg");
  CHECK(r1 * 3 < r0);
  CHECK(h1 > h0);
  CHECK(v1 < 0.01);
}
