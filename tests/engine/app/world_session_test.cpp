// WorldSession (the hot-reload session of `run --watch` and `view`): an edited behaviour is
// reloaded into the modules running it, a broken edit is rejected with file:line, an edited
// world file rebuilds the world, and a world file that fails to load keeps the last good world.
#include "app/world_session.h"

#include <doctest/doctest.h>

#include <chrono>
#include <filesystem>
#include <fstream>

#include "test_world.h"

using namespace rm3d;
namespace fs = std::filesystem;

namespace {

/// Writes the file and moves its time on, so the watcher sees a change whatever the file
/// system's timestamp granularity.
void write(const fs::path& p, const std::string& text) {
  std::error_code ec;
  const auto before = fs::last_write_time(p, ec);
  {
    std::ofstream f(p);
    f << text;
  }
  if (!ec) fs::last_write_time(p, before + std::chrono::seconds(2));
}

}  // namespace

TEST_CASE("world session: reloads behaviours, rebuilds on a world edit, keeps the last good world") {
  const fs::path dir = fs::temp_directory_path() / "rm3d_world_session_test";
  fs::remove_all(dir);
  fs::create_directories(dir);
  const fs::path behaviour = dir / "b.lua", worldFile = dir / "w.lua";
  write(behaviour, "function step(dt) module.joint('pitch'):set_target(0.3) end\n");
  const std::string twoModules =
      "world.set{gravity = {0, 0, 0}}\n"
      "world.spawn('superbot', {behavior = 'b.lua'})\n"
      "world.spawn('superbot', {at = {1, 0, 0}, behavior = 'b.lua'})\n";
  write(worldFile, twoModules);

  WorldSession session(worldFile.string(), test::options(), std::chrono::milliseconds(0));
  REQUIRE(session.load());
  CHECK(session.worldError().empty());
  CHECK(session.world().modules().size() == 2);
  CHECK(session.watchedCount() >= 2);  // the world file and the behaviour, at least
  CHECK(session.poll().empty());       // nothing edited yet
  World* first = &session.world();
  test::stepFor(session.world(), 0.5);

  // An edited behaviour: reloaded into both modules, the world kept.
  write(behaviour, "function step(dt) module.joint('pitch'):set_target(-0.3) end\n");
  SessionChanges c = session.poll();
  REQUIRE(c.reloaded.size() == 1);
  CHECK(c.reloaded[0].modules == 2);
  CHECK(fs::path(c.reloaded[0].file).filename() == "b.lua");
  CHECK_FALSE(c.rebuilt);
  CHECK(&session.world() == first);

  // A broken edit: rejected with file:line, the old code runs on, the error is kept.
  write(behaviour, "function step(dt)\n  module.joint('pitch'):set_target(0.2\nend\n");
  c = session.poll();
  CHECK(c.reloaded.empty());
  REQUIRE(c.rejected.size() == 1);
  CHECK(c.rejected[0].error.find("b.lua:3:") != std::string::npos);
  CHECK(session.reloadErrors().size() == 1);

  // A world file that fails to load: the error names file:line, the last good world runs on.
  write(worldFile, twoModules + "world.spawn('no_such_type')\n");
  c = session.poll();
  CHECK_FALSE(c.rebuilt);
  CHECK(c.worldError.find("w.lua:4:") != std::string::npos);
  CHECK(session.worldError() == c.worldError);
  REQUIRE(session.hasWorld());
  CHECK(&session.world() == first);
  const double t = session.world().time();
  test::stepFor(session.world(), 0.1);
  CHECK(session.world().time() > t);

  // Fixed (and the behaviour too): a new world from the file; the old errors are gone.
  write(behaviour, "function step(dt) end\n");
  write(worldFile, twoModules + "world.spawn('superbot', {at = {2, 0, 0}})\n");
  c = session.poll();
  CHECK(c.rebuilt);
  CHECK(c.worldError.empty());
  CHECK(session.worldError().empty());
  CHECK(session.reloadErrors().empty());
  CHECK(session.world().modules().size() == 3);
  CHECK(session.world().time() == 0);
  fs::remove_all(dir);
}

TEST_CASE("world session: a missing world file is an error naming it; a later save loads it") {
  const fs::path dir = fs::temp_directory_path() / "rm3d_world_session_missing";
  fs::remove_all(dir);
  fs::create_directories(dir);
  const fs::path worldFile = dir / "later.lua";
  WorldSession session(worldFile.string(), test::options(), std::chrono::milliseconds(0));
  CHECK_FALSE(session.load());
  CHECK_FALSE(session.hasWorld());
  CHECK(session.worldError().find("later.lua: cannot read world file (no such file)") != std::string::npos);
  {
    std::ofstream f(worldFile);
    f << "world.spawn('superbot')\n";
  }
  const SessionChanges c = session.poll();
  CHECK(c.rebuilt);
  REQUIRE(session.hasWorld());
  CHECK(session.world().modules().size() == 1);
  fs::remove_all(dir);
}
