// Checks that OffscreenRenderer produces real pixels: a red box on the ground is red in the
// middle of the image, the corners show sky and ground, and PNG errors name the file.
#include "render/offscreen_renderer.h"

#include <doctest/doctest.h>

#include "render_test_util.h"

using rm3d::test::makeBox;
using rm3d::test::pixel;
using rm3d::test::Rgb;

TEST_CASE("OffscreenRenderer draws a red box on the grid ground") {
  rm3d::OffscreenRenderer renderer;
  std::string err;
  REQUIRE_MESSAGE(renderer.init(160, 120, err), err);
  CHECK(renderer.width() == 160);
  CHECK(renderer.height() == 120);
  REQUIRE(renderer.rgba().size() == size_t(160 * 120 * 4));

  rm3d::Snapshot s;
  s.meshes.push_back(makeBox(0.25f, 0.25f, 0.25f));
  rm3d::RenderItem box;
  box.transform(2, 3) = 0.25f;  // resting on z = 0
  box.color = {1.0f, 0.0f, 0.0f, 1.0f};
  s.items.push_back(box);
  rm3d::Camera cam;
  cam.target = {0, 0, 0.25f};
  renderer.draw(s, cam);

  const Rgb centre = pixel(renderer, 80, 60);
  CHECK(centre.r > 100);
  CHECK(centre.r > 2 * centre.g);
  CHECK(centre.r > 2 * centre.b);

  // Top corner: sky, bluish grey. Bottom corner: light-grey ground, not red.
  const Rgb sky = pixel(renderer, 159, 0);
  CHECK(sky.b > sky.r);
  CHECK(sky.b > 150);
  const Rgb ground = pixel(renderer, 0, 119);
  CHECK(ground.r > 120);
  CHECK(std::abs(ground.r - ground.g) < 20);
  CHECK(std::abs(ground.r - ground.b) < 20);

  // Without the box, the centre shows the ground instead of red.
  s.items.clear();
  renderer.draw(s, cam);
  const Rgb empty = pixel(renderer, 80, 60);
  CHECK(std::abs(empty.r - empty.g) < 20);
}

TEST_CASE("OffscreenRenderer draws overlay text and keeps several renderers apart") {
  rm3d::OffscreenRenderer a, b;
  std::string err;
  REQUIRE_MESSAGE(a.init(200, 100, err), err);
  REQUIRE_MESSAGE(b.init(64, 48, err), err);
  auto whitePixels = [](const rm3d::OffscreenRenderer& r) {
    int n = 0;
    for (int y = 0; y < 20; ++y)
      for (int x = 0; x < 60; ++x) {
        const Rgb p = pixel(r, x, y);
        n += p.r > 240 && p.g > 240 && p.b > 240;
      }
    return n;
  };
  rm3d::Snapshot s;
  s.overlay = {"t = 1.00 s"};
  a.draw(s, rm3d::Camera{});
  b.draw(rm3d::Snapshot{}, rm3d::Camera{});  // switches contexts between a's draws
  CHECK(whitePixels(a) > 20);
  s.overlay.clear();
  a.draw(s, rm3d::Camera{});
  CHECK(whitePixels(a) == 0);
  CHECK(b.rgba().size() == size_t(64 * 48 * 4));
}

TEST_CASE("OffscreenRenderer::writePng reports the path when it cannot write") {
  rm3d::OffscreenRenderer renderer;
  std::string err;
  REQUIRE_MESSAGE(renderer.init(32, 24, err), err);
  renderer.draw(rm3d::Snapshot{}, rm3d::Camera{});
  const std::string path = "/nonexistent-rm3d-dir/out.png";
  CHECK_FALSE(renderer.writePng(path, err));
  CHECK(err.find(path) != std::string::npos);
}
