// world.connect: every pair of SuperBot docks, in each of the four orientations, mates face to
// face (centres within 1 mm, normals opposite within 1 degree), and stays so while stepping.
#include <doctest/doctest.h>

#include <string>

#include "docking/dock_frame.h"
#include "test_world.h"

using namespace rm3d;

TEST_CASE("connect mates all 36 SuperBot dock pairs in all four orientations") {
  const char* docks[] = {"front", "back", "left", "right", "up", "down"};
  int checked = 0;
  for (const char* da : docks)
    for (const char* db : docks)
      for (int orient = 0; orient < 4; ++orient) {
        const std::string script = std::string("world.set{gravity={0,0,0}}\n") +
                                   "local a = world.spawn('superbot', {at={0,0,1}, rot={0.3,0.2,0.1}})\n" +
                                   "local b = world.spawn('superbot', {at={2,0,1}})\n" +
                                   "world.connect(a, '" + da + "', b, '" + db + "', " +
                                   std::to_string(orient) + ")\n";
        auto w = test::makeWorld(script);
        const int ia = w->module(0).type->findDock(da), ib = w->module(1).type->findDock(db);
        for (int step = 0; step < 2; ++step) {
          const Pose pa = w->dockPose(0, ia), pb = w->dockPose(1, ib);
          CAPTURE(da);
          CAPTURE(db);
          CAPTURE(orient);
          CHECK((pa.pos - pb.pos).norm() < 0.001);
          CHECK(angleBetween(pa.rot * Vec3::UnitX(), -(pb.rot * Vec3::UnitX())) < 1.0 / kDegPerRad);
          // the faces' reference directions differ by orientation * 90 degrees
          const double turn =
              std::atan2((pa.rot * Vec3::UnitZ()).cross(pb.rot * Vec3::UnitZ()).dot(pa.rot * Vec3::UnitX()),
                         (pa.rot * Vec3::UnitZ()).dot(pb.rot * Vec3::UnitZ()));
          double want = orient * kPi / 2;
          if (want > kPi) want -= 2 * kPi;
          CHECK(std::abs(std::remainder(turn - want, 2 * kPi)) < 1.0 / kDegPerRad);
          CHECK(w->module(0).docks[size_t(ia)].engaged);
          CHECK(w->module(1).docks[size_t(ib)].peerModule == 0);
          test::stepFor(*w, 0.5);
        }
        ++checked;
      }
  CHECK(checked == 144);
}

TEST_CASE("connect refuses an engaged dock and a module docking to itself") {
  CHECK_THROWS_WITH(
      test::makeWorld("local a = world.spawn('superbot')\nlocal b = world.spawn('superbot')\n"
                      "local c = world.spawn('superbot')\nworld.connect(a, 'front', b, 'back')\n"
                      "world.connect(a, 'front', c, 'back')"),
      doctest::Contains("test_world.lua:5: world.connect: dock 'front' of superbot_1 is already engaged"));
  CHECK_THROWS_WITH(
      test::makeWorld("local a = world.spawn('superbot')\nworld.connect(a, 'front', a, 'back')"),
      doctest::Contains("cannot dock to itself"));
  CHECK_THROWS_WITH(
      test::makeWorld("local a = world.spawn('superbot')\nlocal b = "
                      "world.spawn('superbot')\nworld.connect(a, 'nose', b, 'back')"),
      doctest::Contains("no dock named 'nose' on a superbot (it has: front, back, left, right, up, down)"));
}
