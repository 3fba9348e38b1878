// stb_image-backed grayscale loading for heightfields. Every image is read at 16 bits per channel
// (stb widens 8-bit ones exactly: v * 257), so 8- and 16-bit files map to [0, 1] the same way.
#include "assets/height_image.h"

#include <filesystem>
#include <memory>

#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-function"
#pragma GCC diagnostic ignored "-Wsign-compare"
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
// Static, so another translation unit (or libstb) may also carry the implementation.
#define STB_IMAGE_STATIC
#define STB_IMAGE_IMPLEMENTATION
#include <stb/stb_image.h>
#pragma GCC diagnostic pop

namespace fs = std::filesystem;

namespace rm3d {

bool loadGrayImage(const std::string& path, GrayImage& out, std::string& err) {
  out = GrayImage{};
  std::error_code ec;
  if (!fs::exists(path, ec)) {
    err = "'" + path + "' not found";
    return false;
  }
  if (!fs::is_regular_file(path, ec)) {
    err = "'" + path + "' is not a file";
    return false;
  }
  int w = 0, h = 0, channels = 0;
  if (!stbi_info(path.c_str(), &w, &h, &channels)) {
    err = "'" + path + "' is not an image stb_image reads (PNG, JPEG, BMP, TGA, PGM...): " +
          std::string(stbi_failure_reason() ? stbi_failure_reason() : "unknown format");
    return false;
  }
  if (w > kMaxImageSide || h > kMaxImageSide) {
    err = "'" + path + "' is " + std::to_string(w) + " x " + std::to_string(h) + " pixels; at most " +
          std::to_string(kMaxImageSide) + " x " + std::to_string(kMaxImageSide) + " are read";
    return false;
  }
  std::unique_ptr<stbi_us, void (*)(void*)> pixels(stbi_load_16(path.c_str(), &w, &h, &channels, 0),
                                                   stbi_image_free);
  if (!pixels || w < 1 || h < 1 || channels < 1 || channels > 4) {
    err = "'" + path + "' cannot be decoded: " +
          std::string(stbi_failure_reason() ? stbi_failure_reason() : "unknown reason");
    return false;
  }
  const bool colour = channels >= 3;  // 1: gray, 2: gray + alpha, 3: RGB, 4: RGBA
  out.width = w;
  out.height = h;
  out.values.resize(size_t(w) * size_t(h));
  for (size_t i = 0; i < out.values.size(); ++i) {
    const stbi_us* p = pixels.get() + i * size_t(channels);
    if (colour && (p[0] != p[1] || p[1] != p[2])) {
      const size_t x = i % size_t(w), y = i / size_t(w);
      err = "'" + path + "' is a colour image (pixel " + std::to_string(x) + ", " + std::to_string(y) +
            " is not gray); heightfields read grayscale images";
      out = GrayImage{};
      return false;
    }
    out.values[i] = float(double(p[0]) / 65535.0);
  }
  return true;
}

}  // namespace rm3d
