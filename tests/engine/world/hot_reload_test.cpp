// Hot reload: a rewritten behaviour runs in every module using it, `state` survives and
// on_reload() is called; a broken rewrite is rejected with file:line and the old code runs on.
#include <doctest/doctest.h>

#include <filesystem>
#include <fstream>

#include "test_world.h"

using namespace rm3d;
namespace fs = std::filesystem;

namespace {
void write(const fs::path& p, const std::string& text) {
  std::ofstream f(p);
  f << text;
}
}  // namespace

TEST_CASE("a rewritten behaviour takes over, keeping state; a broken one is rejected") {
  const fs::path dir = fs::temp_directory_path() / "rm3d_hot_reload_test";
  fs::create_directories(dir);
  const fs::path file = dir / "nod.lua";
  write(file,
        "state.steps = state.steps or 0\n"
        "function step(dt) state.steps = state.steps + 1; module.joint('pitch'):set_target(0.3) end\n");
  // The world lies beside the behaviour: a script names files in its own folder or the project
  // root (the path rule, docs/limits.md).
  write(dir / "world.lua",
        "world.set{gravity = {0, 0, 0}}\n"
        "world.spawn('superbot', {behavior = 'nod.lua'})\n"
        "world.spawn('superbot', {at = {1, 0, 0}, behavior = 'nod.lua'})\n");
  auto w = std::make_unique<World>(test::options());
  w->loadFile((dir / "world.lua").string());
  test::stepFor(*w, 1.0);
  CHECK(w->jointAngle(0, 0) == doctest::Approx(0.3).epsilon(0.02));

  // New code: drives the other way and reports how many steps the old code counted.
  write(file,
        "function on_reload() state.reloaded_after = state.steps end\n"
        "function step(dt)\n"
        "  state.steps = state.steps + 1\n"
        "  module.joint('pitch'):set_target(state.reloaded_after == 60 and -0.4 or 0)\n"
        "end\n");
  std::vector<std::string> errors;
  CHECK(w->reloadFile(file.string(), errors) == 2);
  CHECK(errors.empty());
  test::stepFor(*w, 1.0);
  // -0.4 only if state.steps survived the reload (60 steps of the old code) and on_reload ran
  CHECK(w->jointAngle(0, 0) == doctest::Approx(-0.4).epsilon(0.02));
  CHECK(w->jointAngle(1, 0) == doctest::Approx(-0.4).epsilon(0.02));

  // A syntax error and a run-time error at load are both rejected; the last good code runs on.
  write(file, "function step(dt)\n  module.joint('pitch'):set_target(0.2\nend\n");
  errors.clear();
  CHECK(w->reloadFile(file.string(), errors) == 0);
  REQUIRE(errors.size() == 1);
  CHECK(errors[0].find("nod.lua:3:") != std::string::npos);
  write(file,
        "local x = nil\nlocal y = x.field\nfunction step(dt) module.joint('pitch'):set_target(0.2) end\n");
  errors.clear();
  CHECK(w->reloadFile(file.string(), errors) == 0);
  REQUIRE(errors.size() == 1);
  CHECK(errors[0].find("nod.lua:2: attempt to index a nil value") != std::string::npos);
  test::stepFor(*w, 0.5);
  CHECK(w->jointAngle(0, 0) == doctest::Approx(-0.4).epsilon(0.02));
  CHECK(w->module(0).fault.empty());
  fs::remove_all(dir);
}
