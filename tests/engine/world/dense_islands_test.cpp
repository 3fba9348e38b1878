// Small islands' contacts solved on their own operator (physics/dense_islands.cpp): they go where
// the sweeps go when both converge, only the islands of one small tree take that way, and the
// bits are the same at any thread count.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "physics/physics_world.h"
#include "test_world.h"

using namespace rm3d;

namespace {

// Three SuperBots (one crawling with the snake gait on its own, one switching its joints, one
// still), an ATRON (one hinge: left to the sweeps), a 3-module snake (nine hinges: one small tree),
// a 5-module one (fifteen: one small tree at a bound of 36 coordinates, left to the sweeps at 16)
// and a 13-module one (39 hinges, 45 coordinates: one small tree at the default bound of 60, left
// to the sweeps at 36).
std::string world(int iterations) {
  return "world.set{duration = 100, seed = 4, solver = \"exact\", solver_iterations = " +
         std::to_string(iterations) + R"(}
world.ground{}
world.spawn("superbot", {at = {0, 0, 0.043}, behavior = "behaviors/snake.lua"})
world.spawn("superbot", {at = {0.5, 0, 0.043}, behavior = "behaviors/alternate.lua"})
world.spawn("superbot", {at = {1.0, 0, 0.043}})
world.spawn("atron", {at = {1.5, 0, 0.056}, behavior = "behaviors/atron_wheel.lua", params = {speed = 1}})
require("snake_chain").build{n = 3, name = "three_", type = "superbot", behavior = "behaviors/snake.lua", at = {0, 0.6, 0.043}}
require("snake_chain").build{n = 5, name = "five_", type = "superbot", behavior = "behaviors/snake.lua", at = {0, 1.2, 0.043}}
require("snake_chain").build{n = 13, name = "thirteen_", type = "superbot", behavior = "behaviors/snake.lua", at = {0, 1.8, 0.043}}
)";
}

struct Run {
  std::vector<Pose> links;
  std::vector<double> angles;
  long dense = 0, steps = 0;
};

Run run(int iterations, bool dense, int threads, double seconds, bool avx = true,
        int coordinates = RunOptions{}.denseCoordinates) {
  RunOptions o = rm3d::test::options();
  o.denseIslands = dense;
  o.denseCoordinates = coordinates;
  o.avx = avx;
  o.threads = threads;
  o.alwaysThreads = threads > 1;
  auto w = rm3d::test::makeWorld(world(iterations), o);
  rm3d::test::stepFor(*w, seconds);
  CHECK(w->faultCount() == 0);
  Run r;
  rm3d::test::collectPoses(*w, r.links, r.angles);
  r.dense = w->physicsConst().denseIslands();
  r.steps = long(w->steps());
  return r;
}

/// The largest distance between the two runs' links [from, to) (all: to = 0).
double largestMove(const Run& a, const Run& b, size_t from = 0, size_t to = 0) {
  REQUIRE(a.links.size() == b.links.size());
  if (to == 0) to = a.links.size();
  double d = 0;
  for (size_t i = from; i < to; ++i) d = std::max(d, (a.links[i].pos - b.links[i].pos).norm());
  return d;
}

/// Every link's pose and every joint's angle the same bits in both runs.
void checkSameBits(const Run& a, const Run& b) {
  REQUIRE(a.links.size() == b.links.size());
  for (size_t i = 0; i < a.links.size(); ++i) {
    CHECK(b.links[i].pos == a.links[i].pos);
    CHECK(b.links[i].rot.coeffs() == a.links[i].rot.coeffs());
  }
  REQUIRE(a.angles.size() == b.angles.size());
  for (size_t i = 0; i < a.angles.size(); ++i) CHECK(b.angles[i] == a.angles[i]);
}

}  // namespace

TEST_CASE("exact solver: a small island's contacts on their own operator go where the sweeps go") {
  // Both converged (400 iterations, 400 sweeps): the same contact impulses, so the three
  // SuperBots' links (their four each come first) move the same to within what the last sweeps
  // leave, 0.02 mm after 1 s. (The 3-module snake parts from its swept twin where a motor reaches
  // its rating, at 0.53 s: the sweeps then take four more at most, the operator sweeps to the
  // end again.) With the motors taken as rigid in the operator (their compliance left out) the
  // SuperBots end 0.28 mm apart.
  const Run dense = run(400, true, 1, 1.0, true, 36), sweeps = run(400, false, 1, 1.0);
  const double apart = largestMove(dense, sweeps, 0, 12);
  MESSAGE("converged, dense against swept: the SuperBots' links " << apart * 1000 << " mm apart after 1 s");
  CHECK(apart < 1e-4);
  // Every substep: the three SuperBots and the 3- and 5-module snakes (one small tree each); not
  // the ATRON (one hinge) nor, at a bound of 36, the 13-module snake, whose links move as without it.
  CHECK(dense.dense == 5 * dense.steps);
  CHECK(sweeps.dense == 0);
  CHECK(largestMove(dense, sweeps, 12, 14) == 0);
  CHECK(largestMove(dense, sweeps, 46) == 0);
}

TEST_CASE(
    "exact solver: trees of up to 60 coordinates on their own operator leave the other islands as they "
    "were") {
  // The default bound, 60 coordinates (a chain of eighteen SuperBots), takes the 13-module snake
  // (45) too, which then moves otherwise. A bound of 36 (a chain of ten) takes the 5-module snake
  // and leaves the 13-module one to the sweeps, where it moves as it does without the operator,
  // bit for bit, though the two snakes are solved in one batch. (Until the contacts' re-sweep after
  // the iterations ended island by island, the batch's islands all stopped when the largest change
  // of any settled: the 13-module snake ended 0.4 mm elsewhere in step 47. A 19-module snake, 63
  // coordinates, still parts from its swept twin by 2.5 mm in steps 26 to 30 when the 5-module one
  // is on its operator: not yet traced.)
  const Run sweeps = run(15, false, 1, 1.0), sixty = run(15, true, 1, 1.0);
  CHECK(sixty.dense == 6 * sixty.steps);
  CHECK(largestMove(sixty, sweeps, 46) > 1e-4);
  const Run dense = run(15, true, 1, 1.0, true, 36);
  CHECK(dense.dense == 5 * dense.steps);
  CHECK(largestMove(dense, sweeps, 26, 46) > 1e-4);
  CHECK(largestMove(dense, sweeps, 12, 14) == 0);
  CHECK(largestMove(dense, sweeps, 46) == 0);
  // And a bound of 16 (up to three docked SuperBots) leaves the 5-module snake to the sweeps.
  const Run sixteen = run(15, true, 1, 1.0, true, 16);
  CHECK(sixteen.dense == 4 * sixteen.steps);
  CHECK(largestMove(sixteen, sweeps, 26, 46) == 0);
}

TEST_CASE("exact solver: a small island's contacts on their own operator, the same bits at 1 and 2 threads") {
  const Run one = run(15, true, 1, 1.0), two = run(15, true, 2, 1.0);
  CHECK(one.dense == 6 * one.steps);
  CHECK(two.dense == one.dense);
  checkSameBits(one, two);
  // And at the defaults the operator's result differs from the sweeps' (it is in use).
  const Run swept = run(15, false, 1, 1.0);
  CHECK(largestMove(one, swept) > 1e-4);
}

TEST_CASE(
    "exact solver: the tree factor's and solve's and the dense operator's SSE2 and AVX variants give the "
    "same "
    "bits") {
  if (!__builtin_cpu_supports("avx")) MESSAGE("this CPU has no AVX: both runs take the SSE2 variants");
  const Run sse2 = run(15, true, 1, 1.0, false), avx = run(15, true, 1, 1.0);
  CHECK(sse2.dense == 6 * sse2.steps);
  checkSameBits(sse2, avx);
  // (And the runs moved: a SuperBot crawled.)
  CHECK(largestMove(sse2, run(15, true, 1, 0.0)) > 1e-3);
}
