// Cloth determinism: the same world gives bit-identical cloth nodes and module poses with 1 and
// 2 behaviour threads, and two such worlds stepped side by side in one process agree too (no
// state shared between worlds, such as Bullet's signed-distance cache, leaks into results), also
// when one of them casts rays through the sheet every step.
#include <doctest/doctest.h>

#include <cstring>
#include <vector>

#include "test_world.h"

namespace {

const char* kWorld = R"(
world.set{seed = 3}
world.ground{}
for i = 0, 3 do
  world.spawn("superbot", {at = {-0.3 + i * 0.2, 0, 0.043}, behavior = "behaviors/snake.lua",
                           params = {index = i, ramp = 0}})
end
world.box{size = {0.1, 0.1, 0.1}, at = {0.3, 0.3, 0.2}, mass = 0.2}
world.cloth{corners = {{-0.5, -0.4, 0.25}, {0.5, -0.4, 0.25}, {0.5, 0.4, 0.25}, {-0.5, 0.4, 0.25}},
            resolution = {20, 16}, mass = 0.08, pinned = {4}}
)";

std::vector<double> state(const rm3d::World& w) {
  std::vector<double> out;
  const rm3d::PhysicsWorld& ph = w.physicsConst();
  for (int i = 0; i < ph.clothNodeCount(0); ++i)
    for (const rm3d::Vec3& v : {ph.clothNode(0, i), ph.clothNodeVelocity(0, i)})
      out.insert(out.end(), {v.x(), v.y(), v.z()});
  for (size_t m = 0; m < w.modules().size(); ++m) {
    const rm3d::Pose p = w.modulePose(int(m));
    out.insert(out.end(), {p.pos.x(), p.pos.y(), p.pos.z(), p.rot.w(), p.rot.x(), p.rot.y(), p.rot.z()});
  }
  return out;
}

bool sameBits(const std::vector<double>& a, const std::vector<double>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(double)) == 0;
}

}  // namespace

TEST_CASE("cloth: identical with 1 and 2 threads, and two worlds side by side") {
  rm3d::RunOptions one = rm3d::test::options(), two = rm3d::test::options();
  two.threads = 2;
  two.chunkSize = 1;
  auto a = rm3d::test::makeWorld(kWorld, one);
  auto b = rm3d::test::makeWorld(kWorld, two);
  auto c = rm3d::test::makeWorld(kWorld, one);
  for (int i = 0; i < 90; ++i) {  // interleaved: the worlds live and step together
    // A ray down through the sheet (a range sensor, a picture) must not change the run.
    a->physicsConst().rayCast(rm3d::Vec3(0.05, 0.05, 1), rm3d::Vec3(0, 0, -1), 2, -1);
    a->step();
    b->step();
    c->step();
  }
  const std::vector<double> sa = state(*a);
  CHECK(sa.size() == 320 * 6 + 4 * 7);
  CHECK(sameBits(sa, state(*b)));
  CHECK(sameBits(sa, state(*c)));
  // It did something: the sheet fell onto the modules, and not through the ground.
  const rm3d::World::ClothStats st = a->clothStats(0);
  CHECK_FALSE(st.nan);
  CHECK(st.hi.z() < 0.2501);                                     // corner 4 is pinned at 0.25
  CHECK(a->physicsConst().clothNode(0, 8 * 20 + 10).z() < 0.2);  // the middle fell
  CHECK(st.lo.z() > -0.001);
}
