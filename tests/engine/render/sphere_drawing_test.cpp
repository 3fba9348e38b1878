// Sphere sets (particles) drawn offscreen: colour where a sphere is and background elsewhere,
// the outline where exact ray casts put it (off axis, and cut by the edge of the view), lit from
// the sun, hidden by a box in front and hiding one behind through the depth of the sphere's
// surface (not of the point it is drawn as), several sets in one frame, buffers reused and
// grown across frames, and sets that draw nothing.
#include <doctest/doctest.h>

#include <cmath>
#include <limits>

#include "render/offscreen_renderer.h"
#include "render/view_math.h"
#include "render_test_util.h"

namespace {

constexpr int kW = 160, kH = 120;

using rm3d::test::makeBox;
using rm3d::test::Rgb;

struct Scene {
  rm3d::OffscreenRenderer renderer;
  rm3d::Camera cam;
  rm3d::Snapshot s;  ///< no ground: sky behind everything

  Scene() {
    std::string err;
    REQUIRE_MESSAGE(renderer.init(kW, kH, err), err);
    cam.eye = {0, -3, 0.5f};  // level, looking along +y at the spheres
    cam.target = {0, 0, 0.5f};
    s.ground = false;
  }
  void draw() { renderer.draw(s, cam); }
  /// The picture of s without its spheres.
  std::vector<uint8_t> background() {
    rm3d::Snapshot empty = s;
    empty.spheres.clear();
    renderer.draw(empty, cam);
    return renderer.rgba();
  }
  /// The pixel (column, row from the top) where a world point lands.
  std::pair<int, int> project(const Eigen::Vector3f& p) const {
    const Eigen::Vector4f c = rm3d::viewProjection(cam, float(kW) / kH) * p.homogeneous();
    return {int((c.x() / c.w() + 1) * 0.5f * kW), int((1 - c.y() / c.w()) * 0.5f * kH)};
  }
  Rgb at(const Eigen::Vector3f& p) const {
    auto [x, y] = project(p);
    REQUIRE(x >= 0);
    REQUIRE(x < kW);
    REQUIRE(y >= 0);
    REQUIRE(y < kH);
    return rm3d::test::pixel(renderer, x, y);
  }
  /// The exact answer: does the ray through pixel (x, y) meet the sphere?
  bool hits(int x, int y, const Eigen::Vector3f& c, float radius) const {
    const rm3d::Ray ray = rm3d::pixelRay(cam, kW, kH, x + 0.5f, y + 0.5f);
    const Eigen::Vector3f oc = ray.origin - c;
    const float b = oc.dot(ray.dir);
    return b * b - (oc.squaredNorm() - radius * radius) >= 0;
  }
};

bool red(Rgb p) {
  return p.r > 60 && p.r > 2 * p.g && p.r > 2 * p.b;
}
bool green(Rgb p) {
  return p.g > 60 && p.g > 2 * p.r && p.g > 2 * p.b;
}
bool same(Rgb a, Rgb b) {
  return std::abs(a.r - b.r) <= 2 && std::abs(a.g - b.g) <= 2 && std::abs(a.b - b.b) <= 2;
}

rm3d::RenderSpheres spheres(std::vector<Eigen::Vector3f> centers, float radius, std::array<float, 4> color) {
  rm3d::RenderSpheres set;
  set.centers = std::move(centers);
  set.radius = radius;
  set.color = color;
  return set;
}

rm3d::RenderItem boxAt(float x, float y, float z) {
  rm3d::RenderItem item;
  item.transform.block<3, 1>(0, 3) = Eigen::Vector3f(x, y, z);
  item.color = {0.0f, 1.0f, 0.0f, 1.0f};
  return item;
}

const std::array<float, 4> kRed{1, 0, 0, 1}, kBlue{0, 0, 1, 1};

}  // namespace

TEST_CASE("sphere sets: sphere colour inside the outline, background outside, lit from the sun") {
  Scene sc;
  rm3d::Snapshot& s = sc.s;
  const std::vector<uint8_t> background = sc.background();

  const Eigen::Vector3f a(-0.6f, 0, 0.5f), b(0.6f, 0, 0.5f);
  s.spheres.push_back(spheres({a, b}, 0.25f, kRed));
  sc.draw();
  for (const Eigen::Vector3f& c : {a, b}) {
    CHECK(red(sc.at(c)));
    // The outline has the sphere's radius: in at 0.85 r, out at 1.2 r, every way round.
    for (const Eigen::Vector3f& d : {Eigen::Vector3f(1, 0, 0), Eigen::Vector3f(0, 0, 1)})
      for (float sign : {-1.0f, 1.0f}) {
        CHECK(red(sc.at(c + d * sign * 0.85f * 0.25f)));
        CHECK(!red(sc.at(c + d * sign * 1.2f * 0.25f)));
      }
    // Shaded as a sphere: the side towards the sun (up) is brighter than the underside.
    CHECK(sc.at(c + Eigen::Vector3f(0, 0, 0.2f)).r > sc.at(c - Eigen::Vector3f(0, 0, 0.2f)).r + 30);
  }
  // Away from the spheres the picture is the background to the pixel.
  auto unchanged = [&](int x, int y) {
    const size_t i = (size_t(y) * kW + x) * 4;
    const uint8_t* p = sc.renderer.rgba().data() + i;
    return same({p[0], p[1], p[2]}, {background[i], background[i + 1], background[i + 2]});
  };
  CHECK(unchanged(sc.project({0, 0, 0.5f}).first, sc.project({0, 0, 0.5f}).second));
  CHECK(unchanged(2, 2));
  CHECK(unchanged(kW - 3, kH - 3));
}

TEST_CASE("sphere sets: off-axis spheres in a wide view keep their whole outline") {
  Scene sc;
  sc.cam.fovyDeg = 110;
  rm3d::Snapshot& s = sc.s;
  // Near the top-right corner, where the outline stretches away from the projected centre.
  const Eigen::Vector3f c(1.1f, -2.0f, 1.3f);
  const float radius = 0.3f;
  s.spheres.push_back(spheres({c}, radius, kRed));
  sc.draw();
  auto redAt = [&](int x, int y) { return red(rm3d::test::pixel(sc.renderer, x, y)); };
  auto hits = [&](int x, int y) { return sc.hits(x, y, c, radius); };
  const auto [cx, cy] = sc.project(c);
  REQUIRE(redAt(cx, cy));
  // Walk outwards (right along the row, up the column) to the last pixel on the sphere.
  int lastRed[2] = {0, 0}, lastHit[2] = {0, 0};
  for (int k = 1; cx + k < kW; ++k) {
    if (redAt(cx + k, cy)) lastRed[0] = k;
    if (hits(cx + k, cy)) lastHit[0] = k;
  }
  for (int k = 1; cy - k >= 0; ++k) {
    if (redAt(cx, cy - k)) lastRed[1] = k;
    if (hits(cx, cy - k)) lastHit[1] = k;
  }
  for (int a = 0; a < 2; ++a) {
    CHECK(lastHit[a] > 8);
    CHECK(std::abs(lastRed[a] - lastHit[a]) <= 1);
  }
}

TEST_CASE("sphere sets: a sphere whose centre has left the view still shows the part in it") {
  Scene sc;
  // The view reaches 1.657 m right of the axis at the spheres' distance: these centres are out.
  for (float x : {1.7f, 1.8f}) {
    CAPTURE(x);
    const Eigen::Vector3f c(x, 0, 0.5f);
    sc.s.spheres = {spheres({c}, 0.3f, kRed)};
    sc.draw();
    int drawn = 0, exact = 0;
    for (int y = 0; y < kH; ++y) {
      drawn += red(rm3d::test::pixel(sc.renderer, kW - 1, y));
      exact += sc.hits(kW - 1, y, c, 0.3f);
    }
    CHECK(exact > 10);
    CHECK(std::abs(drawn - exact) <= 1);
  }
}

TEST_CASE("sphere sets: depth of the surface against boxes in front, behind and cutting through") {
  Scene sc;
  rm3d::Snapshot& s = sc.s;
  const Eigen::Vector3f c(0, 0, 0.5f);
  s.spheres.push_back(spheres({c}, 0.3f, kRed));

  SUBCASE("a box in front hides the sphere where it covers it") {
    s.meshes.push_back(makeBox(0.1f, 0.1f, 0.1f));
    s.items.push_back(boxAt(0, -1, 0.5f));
    sc.draw();
    CHECK(green(sc.at(c)));
    CHECK(red(sc.at(c + Eigen::Vector3f(0.2f, 0, 0))));  // beside the box: the sphere
  }
  SUBCASE("the sphere hides a box behind it") {
    s.meshes.push_back(makeBox(0.6f, 0.1f, 0.6f));
    s.items.push_back(boxAt(0, 1, 0.5f));
    sc.draw();
    CHECK(red(sc.at(c)));
    CHECK(green(sc.at(c + Eigen::Vector3f(0.4f, 0, 0))));  // the box, past the outline
  }
  SUBCASE("a wall through the sphere: the cap in front of it shows, the rim behind it does not") {
    // Wall face at y = -0.17: the sphere's surface is nearer than that within 0.247 m of its
    // axis. Drawn at the depth of its centre the whole sphere would hide; at its front, none.
    s.meshes.push_back(makeBox(1.0f, 0.01f, 1.0f));
    s.items.push_back(boxAt(0, -0.16f, 0.5f));
    sc.draw();
    CHECK(red(sc.at(c)));
    CHECK(red(sc.at(c + Eigen::Vector3f(0.15f, 0, 0))));
    CHECK(red(sc.at(c + Eigen::Vector3f(0, 0, -0.15f))));
    CHECK(green(sc.at(c + Eigen::Vector3f(0.285f, 0, 0))));
    CHECK(green(sc.at(c + Eigen::Vector3f(0, 0, -0.285f))));
  }
}

TEST_CASE("sphere sets: several sets per frame, buffers reused and grown across frames") {
  Scene sc;
  rm3d::Snapshot& s = sc.s;
  const Eigen::Vector3f left(-0.6f, 0, 0.5f), right(0.6f, 0, 0.5f), mid(0, 0, 0.5f);
  s.spheres.push_back(spheres({left}, 0.2f, kRed));
  sc.draw();
  CHECK(red(sc.at(left)));
  CHECK(!red(sc.at(right)));

  // More centres than the buffer held, and a second set in another colour.
  s.spheres[0].centers = {left, right};
  s.spheres.push_back(spheres({mid}, 0.1f, kBlue));
  sc.draw();
  CHECK(red(sc.at(left)));
  CHECK(red(sc.at(right)));
  const Rgb m = sc.at(mid);
  CHECK((m.b > 60 && m.b > 2 * m.r && m.b > 2 * m.g));

  // Fewer: rewritten in place, nothing left over from the last frame.
  s.spheres[0].centers = {right};
  s.spheres.pop_back();
  sc.draw();
  CHECK(!red(sc.at(left)));
  CHECK(red(sc.at(right)));
  CHECK(!(sc.at(mid).b > 2 * sc.at(mid).r + 40));
}

TEST_CASE("sphere sets that draw nothing: empty, zero or NaN radius, the eye inside a sphere") {
  Scene sc;
  rm3d::Snapshot& s = sc.s;
  const std::vector<uint8_t> background = sc.background();
  const float nan = std::numeric_limits<float>::quiet_NaN();
  s.spheres.push_back(spheres({}, 0.2f, kRed));
  s.spheres.push_back(spheres({{0, 0, 0.5f}}, 0.0f, kRed));
  s.spheres.push_back(spheres({{0, 0, 0.5f}}, nan, kRed));
  s.spheres.push_back(spheres({sc.cam.eye}, 0.5f, kRed));  // the camera sits in it
  sc.draw();
  CHECK(sc.renderer.rgba() == background);
  // A NaN centre among good ones leaves the good ones drawn.
  s.spheres.push_back(spheres({{nan, nan, nan}, {0.6f, 0, 0.5f}}, 0.2f, kRed));
  sc.draw();
  CHECK(red(sc.at({0.6f, 0, 0.5f})));
}
