// world.connect: every pair of SuperBot docks, in each of the four orientations, mates face to
// face (centres within 1 mm, normals opposite within 1 degree), and stays so while stepping.
#include <doctest/doctest.h>

#include <string>

#include "docking/dock_frame.h"
#include "test_world.h"

using namespace rm3d;

TEST_CASE("connect mates all 36 SuperBot dock pairs in all four orientations") {
  const char* docks[] = {"front", "back", "left", "right", "up", "down"};
  // Cases in which every condition held at both looks (the CHECKs name the ones that did not): all
  // 144 must mate, so a case that silently skipped its checks would show here.
  int mated = 0;
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
        REQUIRE(ia >= 0);
        REQUIRE(ib >= 0);
        bool held = true;
        for (int step = 0; step < 2; ++step) {
          const Pose pa = w->dockPose(0, ia), pb = w->dockPose(1, ib);
          CAPTURE(da);
          CAPTURE(db);
          CAPTURE(orient);
          const double gap = (pa.pos - pb.pos).norm();
          const double normals = angleBetween(pa.rot * Vec3::UnitX(), -(pb.rot * Vec3::UnitX()));
          // the faces' reference directions differ by orientation * 90 degrees
          const double turn =
              std::atan2((pa.rot * Vec3::UnitZ()).cross(pb.rot * Vec3::UnitZ()).dot(pa.rot * Vec3::UnitX()),
                         (pa.rot * Vec3::UnitZ()).dot(pb.rot * Vec3::UnitZ()));
          double want = orient * kPi / 2;
          if (want > kPi) want -= 2 * kPi;
          const double twist = std::abs(std::remainder(turn - want, 2 * kPi));
          const bool engaged = w->module(0).docks[size_t(ia)].engaged;
          const bool peer = w->module(1).docks[size_t(ib)].peerModule == 0;
          CHECK(gap < 0.001);
          CHECK(normals < 1.0 / kDegPerRad);
          CHECK(twist < 1.0 / kDegPerRad);
          CHECK(engaged);
          CHECK(peer);
          held = held && gap < 0.001 && normals < 1.0 / kDegPerRad && twist < 1.0 / kDegPerRad && engaged &&
                 peer;
          test::stepFor(*w, 0.5);
        }
        if (held) ++mated;
      }
  CHECK(mated == 144);
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

TEST_CASE("dock event kinds carry the contract's names both ways") {
  using rm3d::DockEventKind;
  for (auto [kind, name] :
       {std::pair{DockEventKind::Engaged, "engaged"}, std::pair{DockEventKind::Disengaged, "disengaged"},
        std::pair{DockEventKind::Broken, "broken"}}) {
    CHECK(std::string(rm3d::dockEventName(kind)) == name);
    DockEventKind back = DockEventKind::Engaged;
    CHECK(rm3d::dockEventKindOf(name, back));
    CHECK(back == kind);
  }
  DockEventKind k = DockEventKind::Broken;
  CHECK_FALSE(rm3d::dockEventKindOf("Engaged", k));
  CHECK_FALSE(rm3d::dockEventKindOf("", k));
  CHECK(k == DockEventKind::Broken);
}
