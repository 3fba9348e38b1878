// World: joints (servo, velocity, limits, angle sign), connect, faults and determinism.
#include <doctest/doctest.h>

#include <cmath>
#include <nlohmann/json.hpp>

#include "core/error.h"
#include "io/summary.h"
#include "test_world.h"

using namespace rm3d;
using rm3d::test::makeWorld;
using rm3d::test::stepFor;

namespace {
const char* kSingle = R"(
world.ground{}
world.spawn("superbot", {at = {0, 0, 0.043}})
)";
}

TEST_CASE("a servo reaches a 45 degree target within 2 degrees in 1 s, and the sign is right-handed") {
  auto w = makeWorld(kSingle);
  const Module& m = w->module(0);
  const int pitch = m.type->findJoint("pitch");
  w->setJointCommand(0, pitch, JointMode::Servo, kPi / 4);
  stepFor(*w, 1.0);
  CHECK(std::abs(w->jointAngle(0, pitch) - kPi / 4) < 2.0 / kDegPerRad);
  // angle = rotation of the child (front_outer) relative to the parent about +y
  const double rel = test::relativeAngle(*w, 0, m.type->findLink("front_inner"),
                                         m.type->findLink("front_outer"), Vec3::UnitY());
  CHECK(std::abs(rel - kPi / 4) < 2.0 / kDegPerRad);
}

TEST_CASE("limits hold when a servo target or a velocity drive goes beyond them") {
  auto w = makeWorld(kSingle);
  const Module& m = w->module(0);
  const int roll = m.type->findJoint("roll"), yaw = m.type->findJoint("yaw");
  w->setJointCommand(0, roll, JointMode::Servo, 3.0);
  w->setJointCommand(0, yaw, JointMode::Velocity, -3.0);
  double worstRoll = 0, worstYaw = 0;
  for (int i = 0; i < 180; ++i) {
    w->step();
    worstRoll = std::max(worstRoll, w->jointAngle(0, roll));
    worstYaw = std::min(worstYaw, w->jointAngle(0, yaw));
  }
  CHECK(worstRoll < kPi / 2 + 1.0 / kDegPerRad);
  CHECK(w->jointAngle(0, roll) > kPi / 2 - 2.0 / kDegPerRad);  // it did drive to the limit
  CHECK(worstYaw > -kPi / 2 - 2.0 / kDegPerRad);
  CHECK(w->jointAngle(0, yaw) < -kPi / 2 + 3.0 / kDegPerRad);
}

TEST_CASE("a velocity drive turns at the commanded speed") {
  auto w = makeWorld(kSingle);
  const Module& m = w->module(0);
  const int yaw = m.type->findJoint("yaw");
  w->setJointCommand(0, yaw, JointMode::Velocity, 1.0);
  stepFor(*w, 0.5);
  const double a0 = w->jointAngle(0, yaw);
  stepFor(*w, 0.5);
  CHECK(w->jointAngle(0, yaw) - a0 == doctest::Approx(0.5).epsilon(0.05));
  CHECK(w->jointVelocity(0, yaw) == doctest::Approx(1.0).epsilon(0.05));
}

TEST_CASE("a module rests on the ground at its dock height") {
  auto w = makeWorld(kSingle);
  stepFor(*w, 1.0);
  const Pose p = w->modulePose(0);
  CHECK(p.pos.z() == doctest::Approx(0.043).epsilon(0.05));
  CHECK(std::abs(p.pos.x()) < 0.01);
}

TEST_CASE("a SuperBot colliding with its bracket hulls rests where one with the plates does") {
  const char* kBoth = R"(
world.ground{}
world.spawn("superbot", {at = {0, 0, 0.043}})
world.spawn("tests/modules/superbot_plates.lua", {at = {0.5, 0, 0.043}})
)";
  auto w = makeWorld(kBoth);
  stepFor(*w, 1.0);
  const Pose hull = w->modulePose(0), plates = w->modulePose(1);
  // Flat on both brackets: the front one's D profile and the back one's side plate (outer faces
  // z = -0.042, plus the 1 mm hull margin).
  CHECK(std::abs(hull.pos.z() - plates.pos.z()) < 0.001);
  CHECK(hull.rot.angularDistance(plates.rot) < 0.01);
  CHECK(std::abs(hull.pos.z() - 0.043) < 0.002);
  MESSAGE("rest height: hulls " << hull.pos.z() << " m, plates " << plates.pos.z() << " m; tilt "
                                << hull.rot.angularDistance(plates.rot) << " rad apart");
}

TEST_CASE("an ATRON colliding with its 77-point hulls rests and rolls as one with the 193-point meshes") {
  // Resting on its south pole, and rolled along the ground on its equator by a push: both hulls
  // have the pole and the same 24 points around the equator.
  const char* kBoth = R"(
world.ground{}
local a = world.spawn("atron", {at = {0, 0, 0.06}})
local b = world.spawn("tests/modules/atron_fine.lua", {at = {0, 0.5, 0.06}})
local c = world.spawn("atron", {at = {0, 1, 0.06}, quat = {0.7071068, 0.7071068, 0, 0}})
local d = world.spawn("tests/modules/atron_fine.lua", {at = {0, 1.5, 0.06}, quat = {0.7071068, 0.7071068, 0, 0}})
world.at(0.5, function() c:push({20, 0, 0}) d:push({20, 0, 0}) end)
)";
  auto w = makeWorld(kBoth);
  // The two really collide differently: 77 points against the drawn 193.
  for (const int link : {0, 1}) {
    CHECK(w->module(0).type->links[size_t(link)].collisionShapes()[0].points.size() == 77);
    CHECK(w->module(0).type->links[size_t(link)].shapes[0].points.size() == 193);
    CHECK(w->module(1).type->links[size_t(link)].collisionShapes()[0].points.size() == 193);
  }
  stepFor(*w, 1.0);
  const Pose coarse = w->modulePose(0), fine = w->modulePose(1);
  CHECK(std::abs(coarse.pos.z() - fine.pos.z()) < 0.0005);
  CHECK(std::abs(fine.pos.z() - 0.056) < 0.002);
  stepFor(*w, 1.0);
  const Pose rolledCoarse = w->modulePose(2), rolledFine = w->modulePose(3);
  CHECK(std::abs(rolledCoarse.pos.z() - rolledFine.pos.z()) < 0.0015);
  // Both roll as 24-gons on the equator and lose energy at every vertex; the fine mesh's next
  // ring (11 degrees up, 1 mm off the ground) widens its contact, so it rolls about 14% farther.
  // With the ATRON's rolling resistance (rolling_friction 0.002 m) both roll 0.094 m (0.19 m
  // without it).
  CHECK(std::abs(rolledCoarse.pos.x() - rolledFine.pos.x()) < 0.2 * rolledFine.pos.x());
  CHECK(rolledCoarse.pos.x() > 0.06);
  MESSAGE("ATRON rest height: 77 points " << coarse.pos.z() << " m, 193 points " << fine.pos.z()
                                          << " m; rolled on its side to x = " << rolledCoarse.pos.x()
                                          << " and " << rolledFine.pos.x() << " m");
}

TEST_CASE("separate collision shapes keep masses and inertias: free-floating dynamics are unchanged") {
  // No ground and no gravity, so no contacts: only mass properties and joints shape the motion.
  auto run = [](const char* type) {
    const std::string script =
        std::string("world.set{gravity = {0, 0, 0}}\nworld.spawn('") + type + "', {at = {0, 0, 1}})\n";
    auto w = makeWorld(script);
    const Module& m = w->module(0);
    w->setJointCommand(0, m.type->findJoint("pitch"), JointMode::Servo, 1.0);
    w->setJointCommand(0, m.type->findJoint("yaw"), JointMode::Velocity, -2.0);
    w->setJointCommand(0, m.type->findJoint("roll"), JointMode::Servo, -0.7);
    stepFor(*w, 1.0);
    std::vector<Pose> poses;
    for (size_t l = 0; l < m.type->links.size(); ++l) poses.push_back(w->linkPose(0, int(l)));
    return poses;
  };
  const std::vector<Pose> a = run("superbot"), b = run("tests/modules/superbot_plates.lua");
  REQUIRE(a.size() == b.size());
  for (size_t l = 0; l < a.size(); ++l) {
    CAPTURE(l);
    CHECK((a[l].pos - b[l].pos).norm() < 1e-6);
    CHECK(a[l].rot.angularDistance(b[l].rot) < 1e-5);
  }
  CHECK((a[0].pos - Vec3(0, 0, 1)).norm() > 1e-4);  // it did move
}

TEST_CASE("a crawling snake's stabilisation passes after the first keep the first's factor, and its hinges") {
  // A long chain's first pass leaves 1e-5 to 2e-5 m of its 1e-4 m errors (rows from the substep's
  // start, stale by its motion); a second with the same factor takes that under the tolerance as
  // well as one at the corrected poses does, without making the tree's rows and factor again.
  auto w = makeWorld(R"(world.set{seed = 3}
world.ground{}
require("snake_chain").build{n = 150, type = "superbot", behavior = "behaviors/snake.lua"}
)");
  double gap = 0, angle = 0;
  for (int i = 0; i < 240; ++i) {
    w->step();
    gap = std::max(gap, w->physicsConst().hingeQuality().maxGap);
    angle = std::max(angle, w->physicsConst().hingeQuality().maxAngle);
  }
  const long chord = w->physicsConst().chordPasses(), newton = w->physicsConst().newtonPasses();
  MESSAGE("150-module snake: " << chord << " passes with the first's factor, " << newton
                               << " at the corrected poses; largest hinge gap " << gap << " m, axis angle "
                               << angle << " rad");
  CHECK(w->faultCount() == 0);
  CHECK(chord > 50);
  CHECK(chord > 4 * newton);
  CHECK(gap < 2e-5);
  CHECK(angle < 1e-4);
}

TEST_CASE("SuperBots at any place and heading share their links' compound shapes") {
  // A link's body frame is made in the link's own frame: the same compound for each link of a
  // type, bit for bit, so 36 modules have the compounds of one.
  auto one = makeWorld(R"(world.ground{}
world.spawn("superbot", {at = {0, 0, 0.043}})
)");
  const int perModule = one->physicsConst().compoundCount();
  auto many = makeWorld(R"(world.ground{}
for i = 0, 35 do
  world.spawn("superbot", {at = {(i % 6) * 0.35 - 0.9, (i // 6) * 0.3 + 0.17, 0.043}, rot = {0, 0, 0.37 * i}})
end
)");
  MESSAGE("compounds: " << perModule << " for one SuperBot, " << many->physicsConst().compoundCount()
                        << " for 36");
  CHECK(perModule > 0);
  CHECK(many->physicsConst().compoundCount() == perModule);
  for (int i = 0; i < 60; ++i) many->step();
  CHECK(many->faultCount() == 0);
}

TEST_CASE("spawning an unknown type or a missing behaviour is bad input with file:line") {
  CHECK_THROWS_WITH_AS(makeWorld("world.spawn('superbat')"),
                       doctest::Contains("test_world.lua:1: world.spawn: unknown module type 'superbat'"),
                       InputError);
  CHECK_THROWS_WITH_AS(makeWorld("\nworld.spawn('superbot', {behavior='nope.lua'})"),
                       doctest::Contains("test_world.lua:2: world.spawn: behavior 'nope.lua' not found"),
                       InputError);
  CHECK_THROWS_WITH_AS(makeWorld("world.spawn('superbot', {att={0,0,0}})"),
                       doctest::Contains("unknown option 'att'"), InputError);
  CHECK_THROWS_WITH_AS(makeWorld("world.set{dt='x'}"),
                       doctest::Contains("option 'dt' must be a finite number"), InputError);
}

TEST_CASE("two worlds with the same seed step identically; several worlds live in one process") {
  const char* script = R"(
world.ground{}
local prev
for i = 1, 4 do
  local m = world.spawn("superbot", {behavior = "behaviors/snake.lua", params = {index = i - 1}})
  if prev then world.connect(prev, "back", m, "front") end
  prev = m
end)";
  auto a = makeWorld(script);
  auto b = makeWorld(script);
  for (int i = 0; i < 120; ++i) {
    a->step();
    b->step();
  }
  nlohmann::json ja = runSummary(*a, 0), jb = runSummary(*b, 0);
  CHECK(ja.dump() == jb.dump());
  CHECK(a->modulePose(0).pos.x() != 0.0);
}

TEST_CASE("a named module's random stream does not change when other modules are added") {
  auto a = makeWorld("world.spawn('superbot', {name = 'alpha'})\nworld.spawn('superbot', {name = 'beta'})");
  auto b = makeWorld(
      "world.spawn('superbot', {name = 'extra'})\nworld.spawn('superbot', {name = 'beta'})\n"
      "world.spawn('superbot', {name = 'alpha'})");
  auto c = makeWorld("world.spawn('superbot', {name = 'alpha'})", [] {
    RunOptions o = test::options();
    o.seed = 99;
    return o;
  }());
  Rng ra = a->module(0).rng, rb = b->module(2).rng, rc = c->module(0).rng;
  bool differsWithSeed = false;
  for (int i = 0; i < 10; ++i) {
    const uint64_t x = ra.next();
    CHECK(x == rb.next());
    differsWithSeed |= x != rc.next();
  }
  CHECK(differsWithSeed);
  Rng r0 = a->module(0).rng, r1 = a->module(1).rng;
  CHECK(r0.next() != r1.next());
}
