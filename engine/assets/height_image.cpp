// stb_image-backed grayscale loading for heightfields. Every image is read at 16 bits per channel
// (stb widens 8-bit ones exactly: v * 257), so 8- and 16-bit files map to [0, 1] the same way.
#include "assets/height_image.h"

#include <cstring>
#include <filesystem>
#include <fstream>
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

namespace {

/// Width and height from a PNG's IHDR (the first chunk), for a message when stb_image refuses
/// the file before telling its size.
bool pngSize(const unsigned char* d, size_t n, uint32_t& w, uint32_t& h) {
  static const unsigned char sig[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  if (n < 24 || std::memcmp(d, sig, 8) != 0 || std::memcmp(d + 12, "IHDR", 4) != 0) return false;
  w = uint32_t(d[16]) << 24 | uint32_t(d[17]) << 16 | uint32_t(d[18]) << 8 | d[19];
  h = uint32_t(d[20]) << 24 | uint32_t(d[21]) << 16 | uint32_t(d[22]) << 8 | d[23];
  return true;
}

std::string tooLarge(const std::string& name, const std::string& size) {
  return "'" + name + "' is too large: " + size + "; at most " + std::to_string(kMaxImageSide) + " x " +
         std::to_string(kMaxImageSide) + " pixels are read";
}

}  // namespace

bool decodeGrayImage(const unsigned char* data, size_t size, const std::string& name, GrayImage& out,
                     std::string& err) {
  out = GrayImage{};
  if (size > size_t(kMaxImageBytes)) {
    err = tooLarge(name,
                   std::to_string(size) + " bytes of file (at most " + std::to_string(kMaxImageBytes) + ")");
    return false;
  }
  int w = 0, h = 0, channels = 0;
  uint32_t pw = 0, ph = 0;
  const bool png = pngSize(data, size, pw, ph);
  if (png && (pw > uint32_t(kMaxImageSide) || ph > uint32_t(kMaxImageSide))) {
    err = tooLarge(name, std::to_string(pw) + " x " + std::to_string(ph) + " pixels");
    return false;
  }
  if (!stbi_info_from_memory(data, int(size), &w, &h, &channels)) {
    const char* why = stbi_failure_reason() ? stbi_failure_reason() : "unknown format";
    if (std::strcmp(why, "too large") == 0) {
      err = tooLarge(name, "stb_image refuses its size");
      return false;
    }
    err = "'" + name + "' is not an image stb_image reads (PNG, JPEG, BMP, TGA, PGM...): " + why;
    return false;
  }
  if (w > kMaxImageSide || h > kMaxImageSide) {
    err = tooLarge(name, std::to_string(w) + " x " + std::to_string(h) + " pixels");
    return false;
  }
  std::unique_ptr<stbi_us, void (*)(void*)> pixels(
      stbi_load_16_from_memory(data, int(size), &w, &h, &channels, 0), stbi_image_free);
  if (!pixels || w < 1 || h < 1 || w > kMaxImageSide || h > kMaxImageSide || channels < 1 || channels > 4) {
    err = "'" + name + "' cannot be decoded: " +
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
      err = "'" + name + "' is a colour image (pixel " + std::to_string(x) + ", " + std::to_string(y) +
            " is not gray); heightfields read grayscale images";
      out = GrayImage{};
      return false;
    }
    out.values[i] = float(double(p[0]) / 65535.0);
  }
  return true;
}

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
  // The file's real size bounds what is read (no size field inside it is trusted first).
  const uintmax_t size = fs::file_size(path, ec);
  if (ec) {
    err = "'" + path + "' cannot be read (" + ec.message() + ")";
    return false;
  }
  if (size > uintmax_t(kMaxImageBytes)) {
    err = tooLarge(path,
                   std::to_string(size) + " bytes of file (at most " + std::to_string(kMaxImageBytes) + ")");
    return false;
  }
  std::vector<unsigned char> bytes(static_cast<size_t>(size));
  std::ifstream in(path, std::ios::binary);
  if (!in.read(reinterpret_cast<char*>(bytes.data()), std::streamsize(bytes.size()))) {
    err = "'" + path + "' cannot be read";
    return false;
  }
  return decodeGrayImage(bytes.data(), bytes.size(), path, out, err);
}

}  // namespace rm3d
