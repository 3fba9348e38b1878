// Golden image: tests/worlds/golden_scene.lua rendered offscreen after 1 s must match the
// committed tests/golden/golden_scene.png: mean absolute difference under 2 levels (of 255) per
// channel and fewer than 0.5% of pixels off by more than 40 in any channel. Set
// RM3D_UPDATE_GOLDEN=1 to rewrite the reference after an intended change (and look at it).
#include <doctest/doctest.h>

#include <cstdlib>
#include <filesystem>

#include "io/world_snapshot.h"
#include "render/offscreen_renderer.h"
#include "test_world.h"

#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
#pragma GCC diagnostic ignored "-Wsign-compare"
#pragma GCC diagnostic ignored "-Wunused-function"
#define STB_IMAGE_STATIC
#define STB_IMAGE_IMPLEMENTATION
#include <stb/stb_image.h>
#pragma GCC diagnostic pop

using namespace rm3d;

TEST_CASE("the golden scene renders as the committed reference image") {
  const std::string root = RM3D_SOURCE_DIR;
  auto w = std::make_unique<World>(test::options());
  w->loadFile(root + "/tests/worlds/golden_scene.lua");
  test::stepFor(*w, 1.0);
  OffscreenRenderer r;
  std::string err;
  REQUIRE_MESSAGE(r.init(320, 240, err), err);
  r.draw(buildSnapshot(*w), worldCamera(*w));
  const std::string golden = root + "/tests/golden/golden_scene.png";
  if (std::getenv("RM3D_UPDATE_GOLDEN")) {
    REQUIRE_MESSAGE(r.writePng(golden, err), err);
    MESSAGE("rewrote " << golden);
  }
  int gw = 0, gh = 0, channels = 0;
  unsigned char* ref = stbi_load(golden.c_str(), &gw, &gh, &channels, 4);
  REQUIRE_MESSAGE(ref != nullptr, "cannot read " << golden);
  REQUIRE(gw == 320);
  REQUIRE(gh == 240);
  const std::vector<uint8_t>& img = r.rgba();
  double sum = 0;
  int bad = 0;
  for (int i = 0; i < gw * gh; ++i) {
    int worst = 0;
    for (int c = 0; c < 3; ++c) {
      const int d = std::abs(int(img[size_t(i) * 4 + size_t(c)]) - int(ref[i * 4 + c]));
      sum += d;
      worst = std::max(worst, d);
    }
    bad += worst > 40;
  }
  stbi_image_free(ref);
  const double mean = sum / (gw * gh * 3.0);
  CHECK(mean < 2.0);
  CHECK(bad < gw * gh / 200);
}
