// Divergence: a run whose bodies blow up stops with a message naming the body, the quantity and
// the time; settings that cannot make progress are refused with file:line and the value.
#include <doctest/doctest.h>

#include <cmath>
#include <nlohmann/json.hpp>
#include <string>

#include "core/error.h"
#include "io/summary.h"
#include "test_world.h"
#include "world/world_editor.h"

using namespace rm3d;
using rm3d::test::makeWorld;

namespace {

/// Steps until the world stops (or `maxSteps`), as `rm3d run` does.
void runToEnd(World& w, int maxSteps = 600) {
  for (int i = 0; i < maxSteps && !w.finished(); ++i) w.step();
}

/// Every number the summary holds for a module's pose and joints: a number or a string, never null.
void checkNoNulls(const nlohmann::json& s) {
  for (const auto& m : s["modules"]) {
    for (const auto& v : m["position"]) CHECK_FALSE(v.is_null());
    for (const auto& v : m["orientation"]) CHECK_FALSE(v.is_null());
    for (const auto& [name, v] : m["joints"].items()) CHECK_FALSE(v.is_null());
  }
  CHECK_FALSE(s["sim_time"].is_null());
}

}  // namespace

TEST_CASE(
    "gravity 1e4 and a 1e9 N push: the run stops at the step after the push, naming the module and link") {
  auto w = makeWorld(R"(world.set{gravity = {0, 0, -1e4}, duration = 2}
world.ground{}
local m = world.spawn("superbot", {at = {0, 0, 0.043}, name = "bot"})
world.at(0.5, function() m:push({1e9, 0, 0}) end)
)");
  runToEnd(*w);
  const std::string& msg = w->divergence();
  INFO(msg);
  CHECK(w->fatalFault());
  CHECK(w->stopped());
  CHECK(w->steps() == 31);  // pushed during step 31 (after the hook at t = 0.5 s), not a step more
  CHECK(msg.find("physics diverged at t=0.5167 s (step 31)") == 0);
  CHECK(msg.find("module 'bot' (superbot) link '") != std::string::npos);
  // What: a non-finite state or a speed, named as such.
  CHECK((msg.find("NaN or infinite") != std::string::npos || msg.find("speed") != std::string::npos));
  // Stepping on does nothing.
  w->step();
  CHECK(w->steps() == 31);
  const nlohmann::json s = runSummary(*w, 0);
  CHECK(s["error"] == msg);
  checkNoNulls(s);
}

TEST_CASE(
    "a body falling under gravity 1e4 passes max_speed: the message names the obstacle, the speed and the "
    "time") {
  auto w = makeWorld(R"(world.set{gravity = {0, 0, -1e4}, max_speed = 950}
world.box{size = {0.1, 0.1, 0.1}, at = {0, 0, 5}}
world.box{size = {0.1, 0.1, 0.1}, at = {0, 0, 5}, mass = 1}
)");
  runToEnd(*w);
  const std::string& msg = w->divergence();
  INFO(msg);
  // v = g t passes 950 m/s in step 6 (t = 0.1 s, 1000 m/s) at dt = 1/60.
  CHECK(msg.find("physics diverged at t=0.1 s (step 6): obstacle 2 (a box") == 0);
  CHECK(msg.find("speed 1000 m/s, above max_speed 950 m/s") != std::string::npos);
  CHECK(runSummary(*w, 0)["error"] == msg);
}

TEST_CASE("a body thrown out of the world bounds, and one spun too fast") {
  auto w = makeWorld(R"(world.set{gravity = {0, 0, 0}, bounds = 10}
world.sphere{radius = 0.1, at = {9.5, 0, 0}, mass = 1, velocity = {60, 0, 0}}
)");
  runToEnd(*w);
  INFO(w->divergence());
  CHECK(w->divergence().find("physics diverged at t=0.01667 s (step 1): obstacle 1 (a sphere") == 0);
  CHECK(w->divergence().find("left the world bounds: 10.5 m from the origin, beyond bounds 10 m") !=
        std::string::npos);

  auto spin = makeWorld(R"(world.set{gravity = {0, 0, 0}, max_angular_speed = 5}
local m = world.spawn("superbot", {at = {0, 0, 1}, name = "spinner"})
)");
  // A torque on the root link's body from C++ (the world API pushes forces only).
  spin->start();
  for (int i = 0; i < 60 && !spin->finished(); ++i) {
    WorldEditor(*spin).twistModule(0, Vec3(0, 0, 50));
    spin->step();
  }
  INFO(spin->divergence());
  CHECK(spin->divergence().find("module 'spinner' (superbot) link '") != std::string::npos);
  CHECK(spin->divergence().find("angular speed") != std::string::npos);
}

TEST_CASE("a NaN state stops the run and the summary carries strings, never null") {
  auto w = makeWorld(R"(world.set{gravity = {0, 0, 0}}
world.spawn("superbot", {at = {0, 0, 1}, name = "lost"})
)");
  w->start();
  // A force no binding accepts (they stop at 1e9 N): Bullet's floats overflow.
  WorldEditor(*w).pushModule(0, Vec3(1e38, 0, 0));  // at the root link's centre
  w->step();
  const std::string& msg = w->divergence();
  INFO(msg);
  CHECK(msg.find("physics diverged at t=0.01667 s (step 1): module 'lost'") == 0);
  const nlohmann::json s = runSummary(*w, 0);
  checkNoNulls(s);
  const std::string text = s.dump();
  CHECK(text.find("\"nan\"") != std::string::npos);
  CHECK(s["error"] == msg);
}

TEST_CASE("a healthy world does not diverge") {
  auto w = makeWorld(R"(world.ground{}
world.spawn("superbot", {at = {0, 0, 0.043}})
world.box{size = {0.2, 0.2, 0.2}, at = {1, 0, 0.1}, mass = 2}
)");
  for (int i = 0; i < 120; ++i) w->step();
  CHECK(w->divergence().empty());
  CHECK_FALSE(w->fatalFault());
  CHECK(runSummary(*w, 0)["error"].is_null());
}

TEST_CASE("settings that cannot make progress are bad input naming file:line and the value") {
  struct Case {
    const char* script;  // the bad call is on line 2
    const char* expected;
  };
  const Case cases[] = {
      {"world.set{dt = 1e-300}", "world.set: dt must be between 1e-06 and 1 seconds, got 1e-300"},
      {"world.set{dt = 0}", "dt must be between 1e-06 and 1 seconds, got 0"},
      {"world.set{dt = -0.01}", "got -0.01"},
      {"world.set{dt = 2}", "got 2"},
      {"world.set{dt = 0/0}", "option 'dt' must be a finite number, got "},
      {"world.set{dt = 1/0}", "option 'dt' must be a finite number, got inf"},
      {"world.set{substeps = 0}", "substeps must be 1..1000, got 0"},
      {"world.set{substeps = 1001}", "substeps must be 1..1000, got 1001"},
      {"world.set{solver_iterations = 0}", "solver_iterations must be 1..10000, got 0"},
      {"world.set{solver_iterations = 10001}", "solver_iterations must be 1..10000, got 10001"},
      {"world.set{duration = -1}", "duration must be 0 or more seconds, got -1"},
      {"world.set{duration = 1/0}", "option 'duration' must be a finite number, got inf"},
      {"world.set{gravity = {0, 0, -1e30}}",
       "gravity must be at most 10000 m/s^2 in magnitude (1000 g), got {0, 0, -1e+30}"},
      {"world.set{gravity = {0, 0, 0/0}}", "option 'gravity' must be a table of 3 finite numbers, got "},
      {"world.set{max_speed = 0}", "max_speed must be positive (m/s), got 0"},
      {"world.set{bounds = 1e30}", "bounds must be in (0, 1e+07] metres from the origin, got 1e+30"},
      {"world.every(1e-300, function() end)",
       "world.every: period must be a finite number of seconds >= 1e-06, got 1e-300"},
      {"world.every(0/0, function() end)",
       "world.every: period must be a finite number of seconds >= 1e-06, got "},
      {"world.at(-1, function() end)", "world.at: time must be a finite number of seconds >= 0, got -1"},
      {"world.at(1/0, function() end)", "world.at: time must be a finite number of seconds >= 0, got inf"},
      {"world.box{at = {1e39, 0, 0}}",
       "world.box: 'at' must lie within the world bounds (10000 m from the origin; world.set{bounds=}), got "
       "{1e+39, 0, 0}"},
      {"world.box{size = {1, 1, 0}}",
       "world.box: size must be positive and at most the world bounds (10000 m), got {1, 1, 0}"},
      {"world.box{size = {1e30, 1, 1}}", "got {1e+30, 1, 1}"},
      {"world.box{mass = -1}", "world.box: mass must not be negative (0 is static), got -1"},
      {"world.box{mass = 0/0}", "world.box: option 'mass' must be a finite number, got "},
      {"world.box{mass = 1, velocity = {1e4, 0, 0}}",
       "world.box: velocity must be at most max_speed (1000 m/s; world.set{max_speed=}), got 10000 m/s"},
      {"world.sphere{radius = -1}",
       "world.sphere: radius must be positive and at most the world bounds (10000 m), got -1"},
      {"world.cylinder{length = 0}",
       "world.cylinder: length must be positive and at most the world bounds (10000 m), got 0"},
      {"world.spawn('superbot', {at = {2e4, 0, 0}})",
       "world.spawn: 'at' must lie within the world bounds (10000 m from the origin; world.set{bounds=}), "
       "got {20000, 0, 0}"},
      {"world.spawn('superbot'):push({1e10, 0, 0})",
       "m:push: the force must be at most 1e+09 N in magnitude, got {1e+10, 0, 0} (1e+10 N)"},
      {"world.spawn('superbot'):push({0, 1/0, 0})",
       "m:push: the force must be finite, got component 2 = inf"},
  };
  for (const Case& c : cases) {
    const std::string script = std::string("-- line 1\n") + c.script + "\n";
    INFO(c.script);
    CHECK_THROWS_WITH_AS(makeWorld(script), doctest::Contains("test_world.lua:2: "), InputError);
    CHECK_THROWS_WITH_AS(makeWorld(script), doctest::Contains(c.expected), InputError);
  }
  // NaN is named as such (glibc writes "nan" or "-nan").
  CHECK_THROWS_WITH_AS(makeWorld("world.set{dt = 0/0}"), doctest::Contains("nan"), InputError);
  CHECK_THROWS_WITH_AS(makeWorld("world.every(0/0, function() end)"), doctest::Contains("nan"), InputError);
  // The edges are accepted: dt 1e-6 and 1 s, duration 0, gravity of 1e4, a period of 1e-6 s, time 0, a 1e9 N
  // push.
  CHECK_NOTHROW(makeWorld("world.set{dt = 1e-6}"));
  CHECK_NOTHROW(makeWorld("world.set{dt = 1, duration = 0, gravity = {0, 0, -1e4}}"));
  CHECK_NOTHROW(makeWorld("world.every(1e-6, function() end); world.at(0, function() end)"));
  CHECK_NOTHROW(makeWorld("world.spawn('superbot'):push({1e9, 0, 0})"));
}

TEST_CASE("a world.every period shorter than dt runs once per step and does not hang") {
  auto w = makeWorld(R"(world.set{dt = 0.5, duration = 2}
n = 0
world.every(1e-6, function() n = n + 1 end)
)");
  runToEnd(*w);
  CHECK(w->steps() == 4);
  CHECK(w->scriptError().empty());
}

TEST_CASE("a bad push inside a hook is a world-script error with file:line") {
  auto w = makeWorld(R"(local m = world.spawn("superbot", {at = {0, 0, 1}})
world.at(0.1, function()
  m:push({1e12, 0, 0})
end)
)");
  runToEnd(*w, 30);
  CHECK(w->scriptError().find("test_world.lua:3: m:push: the force must be at most 1e+09 N") !=
        std::string::npos);
  CHECK(w->divergence().empty());
}
