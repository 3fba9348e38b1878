// Particles (engine/particles/particle_system.h): count conservation and a closed tank, the same
// state bit for bit with 1 and 2 threads (fluid and debris, coupled to a body), bodies that
// float or sink, a heap of debris at a plausible angle of repose, and a box slowed by debris.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>
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

/// The heap a 16 x 16 x 16 cm column of 1 cm grains (4096) makes when dropped from 10 cm onto
/// the ground, after `seconds`: its height (top of the highest grain), base radius (holding 95 %
/// of the bottom layer), the slope of its flank (a line through the top of each 1 cm ring, from
/// a fifth to four fifths of the height), and its grains' mean speed.
struct Heap {
  double height = 0, radius = 0, slopeDeg = 0, speed = 0;
};
Heap dropHeap(double friction, double seconds = 5) {
  auto w = rm3d::test::makeWorld(R"(
world.set{duration = 100}
world.ground{friction = 0.8}
world.debris{min = {-0.08, -0.08, 0.1}, max = {0.08, 0.08, 0.26}, spacing = 0.01, friction = )" +
                                 std::to_string(friction) + "}\n");
  rm3d::test::stepFor(*w, seconds);
  const auto& d = *w->particleSystems()[0];
  CHECK(d.nanCount() == 0);
  CHECK(d.count() == 16 * 16 * 16);
  Heap h;
  const double r = d.radius();
  double cx = 0, cy = 0;
  for (int i = 0; i < d.count(); ++i) {
    cx += d.x()[size_t(i)];
    cy += d.y()[size_t(i)];
  }
  cx /= d.count();
  cy /= d.count();
  std::vector<double> base, top(100, 0.0);
  for (int i = 0; i < d.count(); ++i) {
    const double z = d.z()[size_t(i)], rho = std::hypot(d.x()[size_t(i)] - cx, d.y()[size_t(i)] - cy);
    h.height = std::max(h.height, z + r);
    if (z < 3 * r) base.push_back(rho);
    const size_t ring = std::min(size_t(rho / 0.01), top.size() - 1);
    top[ring] = std::max(top[ring], z + r);
  }
  std::sort(base.begin(), base.end());
  h.radius = base.empty() ? 0 : base[base.size() * 95 / 100];
  double n = 0, sr = 0, sz = 0, srr = 0, srz = 0;
  for (size_t k = 0; k < top.size(); ++k)
    if (top[k] > 0.2 * h.height && top[k] < 0.8 * h.height) {
      const double rho = (double(k) + 0.5) * 0.01;
      n += 1;
      sr += rho;
      sz += top[k];
      srr += rho * rho;
      srz += rho * top[k];
    }
  if (n >= 3) h.slopeDeg = -std::atan((n * srz - sr * sz) / (n * srr - sr * sr)) * 180 / 3.14159265358979;
  h.speed = d.meanVelocity().norm();
  return h;
}

TEST_CASE("particles: dropped debris settles into a heap at its angle of repose; frictionless grains spread flat") {
  // Grains with friction 0.6 (as the samples) stand at 25-40 degrees (dry sand: about 34); more
  // friction stands steeper; frictionless grains flow out to one layer.
  const Heap h0 = dropHeap(0.0), h3 = dropHeap(0.3), h6 = dropHeap(0.6), h9 = dropHeap(0.9);
  for (const auto& [mu, h] : {std::pair{0.0, h0}, {0.3, h3}, {0.6, h6}, {0.9, h9}})
    MESSAGE("friction " << mu << ": " << h.height << " m high, base radius " << h.radius << " m, flank "
                        << h.slopeDeg << " deg, atan(height / radius) "
                        << std::atan2(h.height, h.radius) * 180 / 3.14159265358979 << " deg, mean speed "
                        << h.speed << " m/s");
  CHECK(h6.slopeDeg > 20);
  CHECK(h6.slopeDeg < 45);
  CHECK(h6.height > 0.08);       // of a 16 cm column: a heap, not a puddle
  CHECK(h6.speed < 0.005);       // at rest
  CHECK(h0.height < 0.025);      // frictionless: a layer or two
  CHECK(h0.radius > 4 * h6.radius);
  CHECK(h3.height < h6.height);  // the angle rises with friction
  CHECK(h6.height < h9.height + 0.01);
}

TEST_CASE("particles: a box sliding into debris is slowed and shoves the grains; the same state with 1 and 2 threads") {
  // A 10 cm box (2 kg) at 1.5 m/s slides along the ground into a 60 x 60 cm field of 2 cm grains
  // two layers deep, beside a twin on bare ground.
  const std::string script = R"(
world.set{duration = 100}
world.ground{friction = 0.3}
world.debris{min = {0, -0.3, 0}, max = {0.6, 0.3, 0.04}, spacing = 0.02, friction = 0.6}
world.box{size = {0.1, 0.1, 0.1}, at = {-0.2, 0, 0.05}, mass = 2, velocity = {1.5, 0, 0}}
world.box{size = {0.1, 0.1, 0.1}, at = {-0.2, 1.0, 0.05}, mass = 2, velocity = {1.5, 0, 0}}
)";
  rm3d::RunOptions one = rm3d::test::options(), two = one;
  two.threads = 2;
  auto a = rm3d::test::makeWorld(script, one);
  auto b = rm3d::test::makeWorld(script, two);
  const auto& d = *a->particleSystems()[0];
  const int n = d.count();
  const int inPath0 = int(std::count_if(d.y().begin(), d.y().end(), [](float y) { return std::abs(y) < 0.04f; }));
  for (int i = 0; i < 90; ++i) {
    a->step();
    b->step();
  }
  CHECK(a->particleSystems()[0]->stateHash() == b->particleSystems()[0]->stateHash());
  const auto& obs = a->obstacles();
  const double wading = a->obstaclePose(obs[obs.size() - 2].part).pos.x() + 0.2;
  const double bare = a->obstaclePose(obs.back().part).pos.x() + 0.2;
  CHECK(a->obstaclePose(obs[obs.size() - 2].part).pos.x() == b->obstaclePose(b->obstacles()[obs.size() - 2].part).pos.x());
  // The grains that were in the box's path (|y| < 4 cm, ahead of it) are shoved aside or ahead.
  int inPath = 0;
  for (int i = 0; i < n; ++i)
    inPath += std::abs(d.y()[size_t(i)]) < 0.04f && d.x()[size_t(i)] < a->obstaclePose(obs[obs.size() - 2].part).pos.x();
  MESSAGE("box in debris moved " << wading << " m, on bare ground " << bare << " m; grains in its path "
                                 << inPath0 << " -> " << inPath << " (behind it)");
  CHECK(d.count() == n);
  CHECK(d.nanCount() == 0);
  CHECK(wading > 0.15);          // it got in
  CHECK(wading < 0.8 * bare);    // and was slowed
  CHECK(inPath < inPath0 / 4);   // its track is mostly cleared
}
