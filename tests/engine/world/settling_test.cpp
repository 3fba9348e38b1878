// Islands whose contacts settle within a substep's iterations (ExactSolver::planSettling): they
// are swept no more, and end where every iteration would have taken them.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>

#include "physics/physics_world.h"
#include "test_world.h"

using namespace rm3d;

namespace {

// ATRONs on the ground, four spinning their equators (the `atrons_275` scene's), one still; two
// SuperBots, one still and one crawling with the snake gait on its own; a 5-module snake.
const char* const kWorld = R"(
world.set{duration = 100, seed = 4, solver = "exact"}
world.ground{}
for i = 0, 3 do
  world.spawn("atron", {at = {i * 0.16, 0, 0.056}, behavior = "behaviors/atron_wheel.lua", params = {speed = 1}})
end
world.spawn("atron", {at = {0, 0.3, 0.056}})
world.spawn("superbot", {at = {0.5, 0.3, 0.043}})
world.spawn("superbot", {at = {1.0, 0.3, 0.043}, behavior = "behaviors/snake.lua"})
require("snake_chain").build{n = 5, type = "superbot", behavior = "behaviors/snake.lua", at = {0, 1, 0.043}}
)";

struct Run {
  std::vector<Pose> links;
  std::vector<double> angles;
  long sweeps = 0, spared = 0;
};

Run run(bool everyIteration, int threads) {
  RunOptions o = rm3d::test::options();
  o.everyIteration = everyIteration;
  o.threads = threads;
  o.alwaysThreads = threads > 1;
  auto w = rm3d::test::makeWorld(kWorld, o);
  rm3d::test::stepFor(*w, 2.0);
  CHECK(w->faultCount() == 0);
  Run r;
  rm3d::test::collectPoses(*w, r.links, r.angles);
  r.sweeps = w->physicsConst().islandSweeps();
  r.spared = w->physicsConst().sparedSweeps();
  return r;
}

}  // namespace

TEST_CASE("exact solver: a settled island is swept no more and ends where every iteration takes it") {
  const Run settled = run(false, 1), every = run(true, 1);
  // Settling ran (and, asked for every iteration, did not).
  CHECK(settled.spared > 0);
  CHECK(every.spared == 0);
  REQUIRE(settled.links.size() == every.links.size());
  double position = 0, turn = 0, angle = 0;
  for (size_t i = 0; i < settled.links.size(); ++i) {
    position = std::max(position, (settled.links[i].pos - every.links[i].pos).norm());
    turn = std::max(turn, settled.links[i].rot.angularDistance(every.links[i].rot));
  }
  for (size_t i = 0; i < settled.angles.size(); ++i)
    angle = std::max(angle, std::abs(settled.angles[i] - every.angles[i]));
  MESSAGE("settling: " << settled.spared << " of " << settled.sweeps + settled.spared
                       << " island sweeps spared; largest difference after 2 s: " << position << " m, "
                       << turn << " rad of a link, " << angle << " rad of a joint");
  CHECK(position < 1e-7);
  CHECK(turn < 1e-6);
  CHECK(angle < 1e-6);
  // The same bits at 2 threads (each island settles by its own rows, in whatever batch).
  const Run two = run(false, 2);
  CHECK(two.spared == settled.spared);
  for (size_t i = 0; i < settled.links.size(); ++i) {
    CHECK(two.links[i].pos == settled.links[i].pos);
    CHECK(two.links[i].rot.coeffs() == settled.links[i].rot.coeffs());
  }
}
