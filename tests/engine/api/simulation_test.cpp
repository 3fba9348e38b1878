// The public engine API (engine/api/rm3d/simulation.h): a Batch's worlds on threads are the same
// worlds stepped one by one, bit for bit (run under ThreadSanitizer by .ci/tsan: worlds are built
// and stepped concurrently); a snapshot re-runs to the same bits, and arrays held from before a
// restore stay the world's; errors carry RM3D's messages, a failing hook's with its file and line.
#include "rm3d/simulation.h"

#include <doctest/doctest.h>

#include <cmath>
#include <string>
#include <vector>

using rm3d::api::Batch;
using rm3d::api::Error;
using rm3d::api::Options;
using rm3d::api::Simulation;

namespace {

const std::string kSnake = std::string(RM3D_SOURCE_DIR) + "/worlds/snake.lua";

Options snake(int modules, uint64_t seed) {
  Options o;
  o.seed = seed;
  o.params["modules"] = std::to_string(modules);
  o.policy = true;
  return o;
}

/// A fixed policy: every world's first action column follows a sine of the step.
void act(rm3d::api::AgentArrays& a, int k) {
  for (int r = 0; r < a.rows; ++r)
    if (a.actDim > 0) a.act[size_t(r) * size_t(a.actDim)] = 0.4 * std::sin(0.2 * k + r);
}

}  // namespace

TEST_CASE("a Batch at 2 threads equals 1 thread and the same Simulations stepped one by one") {
  const std::vector<int> sizes = {3, 5, 4, 6};
  std::vector<std::string> paths(sizes.size(), kSnake);
  std::vector<Options> options;
  for (size_t i = 0; i < sizes.size(); ++i) options.push_back(snake(sizes[i], 10 + i));
  auto run = [&](int threads) {
    Batch b(paths, options, threads);
    for (int k = 0; k < 30; ++k) {
      act(*b.arrays(), k);
      b.step(1);
    }
    std::vector<std::string> out;
    for (int i = 0; i < b.size(); ++i) out.push_back(b.world(i).summaryJson());
    auto a = b.arrays();
    out.emplace_back(reinterpret_cast<const char*>(a->obs.data()), a->obs.size() * sizeof(double));
    return out;
  };
  const auto one = run(1), two = run(2);
  REQUIRE(one.size() == two.size());
  for (size_t i = 0; i < one.size() - 1; ++i) {
    // The summaries differ only in wall_seconds: compare without it.
    auto strip = [](std::string s) {
      return s.substr(0, s.find("\"wall_seconds\"")) + s.substr(s.find(",", s.find("\"wall_seconds\"")));
    };
    CHECK(strip(one[i]) == strip(two[i]));
  }
  CHECK(one.back() == two.back());
  // World 2 alone, with its own arrays (4 modules: its rows are the first 4 of its slot).
  auto w = Simulation::open(kSnake, options[2]);
  for (int k = 0; k < 30; ++k) {
    auto a = w->arrays();
    for (int r = 0; r < a->rows; ++r)
      a->act[size_t(r) * size_t(a->actDim)] = 0.4 * std::sin(0.2 * k + (2 * 6 + r));
    w->step(1);
  }
  auto a = w->arrays();
  const auto* batchObs =
      reinterpret_cast<const double*>(one.back().data()) + size_t(2 * 6) * size_t(a->obsDim);
  for (size_t k = 0; k < a->obs.size(); ++k) CHECK(a->obs[k] == batchObs[k]);
}

TEST_CASE("Batch::reset restores the start on 2 threads: the worlds then run as fresh ones, bit for bit") {
  // Restores run in parallel and share the batch's parsed meshes (the sanitizer builds run this).
  const std::vector<int> sizes = {3, 5, 4};
  std::vector<std::string> paths(sizes.size(), kSnake);
  std::vector<Options> options;
  for (size_t i = 0; i < sizes.size(); ++i) options.push_back(snake(sizes[i], 20 + i));
  auto drive = [](Batch& b, int steps) {
    for (int k = 0; k < steps; ++k) {
      act(*b.arrays(), k);
      b.step(1);
    }
    return b.arrays()->obs;
  };
  Batch fresh(paths, options, 1);
  const std::vector<double> want = drive(fresh, 20);
  Batch b(paths, options, 2);
  const std::vector<double> start = b.arrays()->obs;
  drive(b, 35);
  b.reset({0, 1, 0});
  CHECK(b.world(0).steps() == 35);
  CHECK(b.world(1).steps() == 0);
  b.reset({});
  for (int i = 0; i < b.size(); ++i) CHECK(b.world(i).steps() == 0);
  CHECK(b.arrays()->obs == start);
  CHECK(drive(b, 20) == want);
  // Worlds that keep no inputs (no snapshot to restore) are opened again: the same start.
  for (Options& o : options) o.snapshots = false;
  Batch noLog(paths, options, 2);
  drive(noLog, 10);
  noLog.reset({});
  CHECK(noLog.world(1).steps() == 0);
  CHECK(noLog.arrays()->obs == start);
}

TEST_CASE("a snapshot re-runs to the same bits, at another thread count") {
  auto a = Simulation::open(kSnake, snake(4, 3));
  auto b = Simulation::open(kSnake, snake(4, 3));
  for (int k = 0; k < 40; ++k) {
    act(*a->arrays(), k);
    a->step(1);
    if (k < 25) {
      act(*b->arrays(), k);
      b->step(1);
    }
  }
  auto c = Simulation::fromSnapshot(b->snapshot(), 2);
  CHECK(c->steps() == 25);
  for (int k = 25; k < 40; ++k) {
    act(*c->arrays(), k);
    c->step(1);
  }
  CHECK(c->arrays()->obs == a->arrays()->obs);
  CHECK(c->metrics() == a->metrics());
}

TEST_CASE("API errors carry RM3D's messages") {
  CHECK_THROWS_WITH_AS(Simulation::open("/no/such/world.lua", Options{}), doctest::Contains("no such file"),
                       Error);
  CHECK_THROWS_WITH_AS(Simulation::fromSnapshot("not a snapshot"), doctest::Contains("not an RM3D snapshot"),
                       Error);
  auto w = Simulation::open(kSnake, snake(2, 1));
  w->arrays()->act[0] = std::nan("");
  CHECK_THROWS_WITH_AS(w->step(1), doctest::Contains("act[0][0] is nan"), Error);
  w->close();
  CHECK_THROWS_WITH_AS(w->step(1), doctest::Contains("closed"), Error);
}

TEST_CASE("arrays held from before a restore go on driving the world") {
  auto a = Simulation::open(kSnake, snake(4, 3));
  for (int k = 0; k < 40; ++k) {
    act(*a->arrays(), k);
    a->step(1);
  }
  auto b = Simulation::open(kSnake, snake(4, 3));
  const auto held = b->arrays();  // as a Python view keeps them
  for (int k = 0; k < 25; ++k) {
    act(*held, k);
    b->step(1);
  }
  const std::string snap = b->snapshot();
  for (int k = 25; k < 35; ++k) {
    act(*held, k);
    b->step(1);
  }
  b->restore(snap);
  CHECK(b->arrays() == held);
  for (int k = 25; k < 40; ++k) {
    act(*held, k);
    b->step(1);
  }
  CHECK(held->obs == a->arrays()->obs);
  CHECK(b->metrics() == a->metrics());
}

TEST_CASE("a hook that fails while the arrays are read raises, naming its file and line") {
  Options o;
  o.policy = true;
  o.root = RM3D_SOURCE_DIR;
  auto w = Simulation::fromString("world.spawn('superbot')\nworld.reward(function(t)\n  return 0 / t\nend)\n",
                                  "rw", o);
  CHECK_THROWS_WITH_AS(w->arrays(), doctest::Contains("rw:2: world.reward's function returned a number"),
                       Error);
  CHECK(w->arrays()->reward[0] == 0.0);  // nothing of what it returned is handed on
}
