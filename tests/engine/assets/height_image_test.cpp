// Checks loadGrayImage on the committed images (assets/terrain/make_terrain.lua makes them):
// gray values map to [0, 1] exactly as 8-bit v / 255, rows run from the top of the picture, a
// colour image and non-images are refused with the path in the message.
#include "assets/height_image.h"

#include <doctest/doctest.h>

#include <string>

namespace {
const std::string kRoot = RM3D_SOURCE_DIR;
}

TEST_CASE("a grayscale PNG reads as values in [0, 1], row by row from the top") {
  rm3d::GrayImage img;
  std::string err;
  REQUIRE(rm3d::loadGrayImage(kRoot + "/tests/worlds/terrain_steps.png", img, err));
  CHECK(img.width == 30);
  CHECK(img.height == 30);
  REQUIRE(img.values.size() == 900);
  // Columns 0-7 black, 12-17 gray 128, 22-29 white, in every row.
  for (int y : {0, 15, 29}) {
    CHECK(img.values[size_t(y * 30 + 3)] == 0.0f);
    CHECK(img.values[size_t(y * 30 + 14)] == doctest::Approx(128.0 / 255.0).epsilon(1e-6));
    CHECK(img.values[size_t(y * 30 + 25)] == 1.0f);
  }
  REQUIRE(rm3d::loadGrayImage(kRoot + "/assets/terrain/hills_30.png", img, err));
  CHECK(img.width * img.height == 900);
}

TEST_CASE("colour images, non-images, folders and missing files are refused, naming the path") {
  rm3d::GrayImage img;
  std::string err;
  CHECK_FALSE(rm3d::loadGrayImage(kRoot + "/tests/bad_inputs/world/heightfield_colour.png", img, err));
  CHECK(err.find("heightfield_colour.png") != std::string::npos);
  CHECK(err.find("colour") != std::string::npos);
  CHECK(img.values.empty());
  CHECK_FALSE(rm3d::loadGrayImage(kRoot + "/README.md", img, err));
  CHECK(err.find("not an image") != std::string::npos);
  CHECK_FALSE(rm3d::loadGrayImage(kRoot + "/assets", img, err));
  CHECK(err.find("not a file") != std::string::npos);
  CHECK_FALSE(rm3d::loadGrayImage(kRoot + "/no_such.png", img, err));
  CHECK(err.find("no_such.png' not found") != std::string::npos);
}

TEST_CASE("a PNG whose header claims 65535 x 65535 pixels is 'too large', read from the header") {
  rm3d::GrayImage img;
  std::string err;
  CHECK_FALSE(rm3d::loadGrayImage(kRoot + "/tests/bad_inputs/world/heightfield_huge.png", img, err));
  CHECK(err.find("heightfield_huge.png' is too large: 65535 x 65535 pixels; at most 1024 x 1024") !=
        std::string::npos);
  CHECK(img.values.empty());
  // The same bytes in memory, and a header cut short: a message, never an allocation.
  const unsigned char header[] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n', 0, 0, 0,    13,
                                  'I',  'H', 'D', 'R', 0,    0,    0xff, 0xff, 0, 0, 0xff, 0xff};
  CHECK_FALSE(rm3d::decodeGrayImage(header, sizeof header, "mem.png", img, err));
  CHECK(err.find("'mem.png' is too large: 65535 x 65535 pixels") == 0);
  CHECK_FALSE(rm3d::decodeGrayImage(header, 10, "short.png", img, err));
  CHECK(err.find("'short.png' is not an image") == 0);
}
