// Particles (engine/particles/particle_system.h): count conservation and a closed tank, the same
// state bit for bit with 1 and 2 threads (fluid and debris, coupled to a body), bodies that
// float or sink, a heap of debris at a plausible angle of repose, and a box slowed by debris.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <map>
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

/// A container of separate static boxes of thickness T as worlds/fluid.lua builds its tank: the
/// side walls (+-y) run the container's length and cover the corners, the end walls (+-x) fit
/// between them, so each end wall's faces at +-y lie in a side wall (a seam two boxes share), and
/// a floor or lid fits between all four (seams on every side). Interior half extents (hx, hy, hz),
/// turned by roll, pitch, yaw about its centre c; `lid`: closed on top too, and `floor`: a floor
/// box (else the ground is the floor, and the container stands on it). A dam of fluid (spacing
/// s, more options in `extra`) fills the world-aligned box lo..hi.
std::string container(const rm3d::Vec3& c, const rm3d::Vec3& half, double T, const rm3d::Vec3& rpy,
                      bool floor, bool lid, const rm3d::Vec3& lo, const rm3d::Vec3& hi, double s,
                      const std::string& extra = "") {
  auto num = [](double x) { return std::to_string(x); };
  auto vec = [&](const rm3d::Vec3& v) {
    return "{" + num(v.x()) + ", " + num(v.y()) + ", " + num(v.z()) + "}";
  };
  std::string out = "world.set{duration = 100}\n";
  if (!floor) out += "world.ground{}\n";
  out += "local c, h, T, rpy = " + vec(c) + ", " + vec(half) + ", " + num(T) + ", " + vec(rpy) + "\n";
  out += R"(
local cr, sr, cp, sp, cy, sy = math.cos(rpy[1]), math.sin(rpy[1]), math.cos(rpy[2]), math.sin(rpy[2]),
                               math.cos(rpy[3]), math.sin(rpy[3])
-- Rz(yaw) Ry(pitch) Rx(roll), as world.box's rot.
local R = {{cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr},
           {sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr},
           {-sp, cp * sr, cp * cr}}
local function wall(size, at)
  local w = {}
  for i = 1, 3 do w[i] = c[i] + R[i][1] * at[1] + R[i][2] * at[2] + R[i][3] * at[3] end
  world.box{size = size, at = w, rot = rpy}
end
local X, Y, Z = 2 * h[1] + 2 * T, 2 * h[2], 2 * h[3] + 2 * T
wall({X, T, Z}, {0, h[2] + T / 2, 0})
wall({X, T, Z}, {0, -h[2] - T / 2, 0})
wall({T, Y, Z}, {h[1] + T / 2, 0, 0})
wall({T, Y, Z}, {-h[1] - T / 2, 0, 0})
)";
  if (floor) out += "wall({2 * h[1], Y, T}, {0, 0, -h[3] - T / 2})\n";
  if (lid) out += "wall({2 * h[1], Y, T}, {0, 0, h[3] + T / 2})\n";
  if (s > 0)
    out += "world.fluid{min = " + vec(lo) + ", max = " + vec(hi) + ", spacing = " + num(s) + extra + "}\n";
  return out;
}

/// Particles of system 0 outside the container's interior (shrunk by `slack`, in its frame).
int outside(const World& w, const rm3d::Vec3& c, const rm3d::Vec3& half, const rm3d::Vec3& rpy,
            double slack) {
  const rm3d::Quat q = rm3d::quatFromRpy(rpy.x(), rpy.y(), rpy.z());
  const auto& ps = *w.particleSystems()[0];
  int n = 0;
  for (int i = 0; i < ps.count(); ++i) {
    const rm3d::Vec3 x(ps.x()[size_t(i)], ps.y()[size_t(i)], ps.z()[size_t(i)]);
    const rm3d::Vec3 l = q.conjugate() * (x - c);
    bool in = true;
    for (int a = 0; a < 3; ++a) in = in && std::abs(l[a]) <= half[a] - slack;
    n += in ? 0 : 1;
  }
  return n;
}

/// The fluid's surface height: over the columns a spacing wide (those within `skip` of the origin
/// in both x and y left out), the median of the highest particle's top.
double surfaceHeight(const rm3d::ParticleSystem& ps, double skip) {
  const double s = 2 * ps.radius();
  std::map<std::pair<long, long>, double> top;
  for (int i = 0; i < ps.count(); ++i) {
    const double x = ps.x()[size_t(i)], y = ps.y()[size_t(i)], z = ps.z()[size_t(i)];
    if (std::abs(x) < skip && std::abs(y) < skip) continue;
    double& t = top[{std::lround(std::floor(x / s)), std::lround(std::floor(y / s))}];
    t = std::max(t, z);
  }
  std::vector<double> h;
  for (const auto& [cell, z] : top) h.push_back(z);
  std::sort(h.begin(), h.end());
  return h.empty() ? 0 : h[h.size() / 2] + ps.radius();
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

TEST_CASE("particles: a dam break keeps every particle in a tank of overlapping wall boxes") {
  // worlds/fluid.lua in small: four walls standing on the ground, their ends overlapping at the
  // corners (where the wave used to press particles through the seam of two boxes), and no lid
  // (the walls are high enough). 2,250 particles, 3 s.
  const rm3d::Vec3 c(0, 0, 0.4), half(0.3, 0.15, 0.4), zero(0, 0, 0);
  auto w = rm3d::test::makeWorld(
      container(c, half, 0.1, zero, false, false, {-0.3, -0.15, 0}, {-0.1, 0.15, 0.3}, 0.02));
  const auto& fluid = *w->particleSystems()[0];
  CHECK(fluid.count() == 10 * 15 * 15);
  CHECK(outside(*w, c, half, zero, 0.009) == 0);
  int worst = 0;
  for (int k = 0; k < 30; ++k) {
    rm3d::test::stepFor(*w, 0.1);
    worst = std::max(worst, outside(*w, c, half, zero, 0.009));
  }
  CHECK(fluid.nanCount() == 0);
  CHECK(worst == 0);
}

TEST_CASE("particles: a turned and tilted closed box of six thin overlapping walls keeps every particle") {
  // No ground: a floor and a lid of their own, walls 3 cm thick (less than half a step at the
  // 4 m/s speed limit), the box turned 0.5 rad and tilted 0.25 rad so the water runs down its
  // length into a corner where three walls meet. 3,136 particles, 3 s.
  const rm3d::Vec3 c(0, 0, 1), half(0.45, 0.2, 0.25), rpy(0.15, 0.25, 0.5);
  auto w = rm3d::test::makeWorld(
      container(c, half, 0.03, rpy, true, true, {-0.32, -0.16, 0.92}, {-0.18, -0.02, 1.08}, 0.01));
  const auto& fluid = *w->particleSystems()[0];
  CHECK(fluid.count() == 14 * 14 * 16);
  CHECK(outside(*w, c, half, rpy, 0.0045) == 0);
  int worst = 0;
  for (int k = 0; k < 30; ++k) {
    rm3d::test::stepFor(*w, 0.1);
    worst = std::max(worst, outside(*w, c, half, rpy, 0.0045));
  }
  CHECK(fluid.nanCount() == 0);
  CHECK(worst == 0);
}

/// A pool `layers` deep at spacing s in a tank of wall boxes (20 x 20 columns), after 3 s at rest:
/// how much lower its surface is than the height it was poured at (a share).
double poolCompression(double s, int layers, const std::string& extra) {
  const double W = 20 * s;
  auto w = rm3d::test::makeWorld(container({0, 0, 0.5}, {W / 2, W / 2, 0.5}, 0.1, {0, 0, 0}, false, false,
                                           {-W / 2, -W / 2, 0}, {W / 2, W / 2, layers * s}, s, extra));
  const auto& ps = *w->particleSystems()[0];
  CHECK(ps.count() == 400 * layers);
  rm3d::test::stepFor(*w, 3);
  CHECK(ps.nanCount() == 0);
  return 1 - surfaceHeight(ps, 0) / (layers * s);
}

TEST_CASE("particles: a deep pool at rest keeps most of its height (a substep per iteration)") {
  // 10 layers at worlds/fluid.lua's spacing (1.4 cm): the three iterations in one step leave the
  // pool about a fifth lower (0.18); split into three substeps, 0.06. At 1 cm (gravity moves a
  // particle by a quarter of the spacing in a step), 0.12.
  const double one = poolCompression(0.014, 10, ", substeps = 1");
  const double three = poolCompression(0.014, 10, "");
  const double fine = poolCompression(0.01, 10, "");
  MESSAGE("10 layers compressed: 1.4 cm, one step " << one << ", three substeps " << three
                                                    << "; 1 cm, three substeps " << fine);
  CHECK(three < 0.08);
  CHECK(three < one / 2);
  CHECK(fine < 0.14);
}

TEST_CASE("particles: a box of half the fluid's density floats about half submerged; a dense one sinks") {
  auto light = rm3d::test::makeWorld(tank(500, false));
  auto heavy = rm3d::test::makeWorld(tank(2000, false));
  rm3d::test::stepFor(*light, 4);
  rm3d::test::stepFor(*heavy, 4);
  const double surface = surfaceHeight(*light->particleSystems()[0], 0.08);  // away from the box
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

TEST_CASE(
    "particles: dropped debris settles into a heap at its angle of repose; frictionless grains spread flat") {
  // Grains with friction 0.6 (as the samples) stand at 25-40 degrees (dry sand: about 34); more
  // friction stands steeper; frictionless grains flow out to one layer.
  const Heap h0 = dropHeap(0.0), h3 = dropHeap(0.3), h6 = dropHeap(0.6), h9 = dropHeap(0.9);
  for (const auto& [mu, h] : {std::pair{0.0, h0}, {0.3, h3}, {0.6, h6}, {0.9, h9}})
    MESSAGE("friction " << mu << ": " << h.height << " m high, base radius " << h.radius << " m, flank "
                        << h.slopeDeg << " deg, atan(height / radius) "
                        << std::atan2(h.height, h.radius) * 180 / 3.14159265358979 << " deg, mean speed "
                        << h.speed << " m/s");
  // The heap as a cone: atan(height / base radius). The flank fit through 1 cm rings swings
  // between 15 and 33 degrees with small changes in the contacts on the same heap (0.10 m high,
  // 0.17 m across), so the cone's angle is the one checked.
  const double cone6 = std::atan2(h6.height, h6.radius) * 180 / 3.14159265358979;
  CHECK(cone6 > 20);
  CHECK(cone6 < 45);
  CHECK(h6.height > 0.08);   // of a 16 cm column: a heap, not a puddle
  CHECK(h6.speed < 0.005);   // at rest
  CHECK(h0.height < 0.025);  // frictionless: a layer or two
  CHECK(h0.radius > 4 * h6.radius);
  CHECK(h3.height < h6.height);  // the angle rises with friction
  CHECK(h6.height < h9.height + 0.01);
}

TEST_CASE(
    "particles: a box sliding into debris is slowed and shoves the grains; the same state with 1 and 2 "
    "threads") {
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
  const int inPath0 =
      int(std::count_if(d.y().begin(), d.y().end(), [](float y) { return std::abs(y) < 0.04f; }));
  for (int i = 0; i < 90; ++i) {
    a->step();
    b->step();
  }
  CHECK(a->particleSystems()[0]->stateHash() == b->particleSystems()[0]->stateHash());
  const auto& obs = a->obstacles();
  const double wading = a->obstaclePose(obs[obs.size() - 2].part).pos.x() + 0.2;
  const double bare = a->obstaclePose(obs.back().part).pos.x() + 0.2;
  CHECK(a->obstaclePose(obs[obs.size() - 2].part).pos.x() ==
        b->obstaclePose(b->obstacles()[obs.size() - 2].part).pos.x());
  // The grains that were in the box's path (|y| < 4 cm, ahead of it) are shoved aside or ahead.
  int inPath = 0;
  for (int i = 0; i < n; ++i)
    inPath += std::abs(d.y()[size_t(i)]) < 0.04f &&
              d.x()[size_t(i)] < a->obstaclePose(obs[obs.size() - 2].part).pos.x();
  MESSAGE("box in debris moved " << wading << " m, on bare ground " << bare << " m; grains in its path "
                                 << inPath0 << " -> " << inPath << " (behind it)");
  CHECK(d.count() == n);
  CHECK(d.nanCount() == 0);
  CHECK(wading > 0.15);         // it got in
  CHECK(wading < 0.8 * bare);   // and was slowed
  CHECK(inPath < inPath0 / 4);  // its track is mostly cleared
}
