// Reads grayscale images (PNG, and whatever else stb_image reads) as heights for terrain: the
// only image reader in the engine.
#pragma once

#include <string>
#include <vector>

namespace rm3d {

struct GrayImage {
  int width = 0, height = 0;
  /// width * height values in [0, 1] (black 0, white 1), row after row from the top of the
  /// picture, each row from left to right. 16-bit images keep their precision.
  std::vector<float> values;
};

/// Loads `path` as a grayscale image. An image with colour channels is accepted when every pixel
/// is gray (red = green = blue); alpha is ignored. On failure returns false and sets err to
/// "'<path>' <reason>" (not found, a folder, not an image stb_image reads, a colour image, too
/// large); out is then left empty.
bool loadGrayImage(const std::string& path, GrayImage& out, std::string& err);

/// The largest image side loadGrayImage accepts (pixels).
constexpr int kMaxImageSide = 1024;
/// The largest image file read (bytes): far above any 1024 x 1024 image, far below memory.
constexpr long long kMaxImageBytes = 64ll << 20;

/// The decoder loadGrayImage uses, on bytes in memory (`name` for messages); the fuzz target's
/// entry point. Sizes in the image's header are checked before pixels are allocated.
bool decodeGrayImage(const unsigned char* data, size_t size, const std::string& name, GrayImage& out,
                     std::string& err);

}  // namespace rm3d
