// Fuzzes the heightfield image decoder (assets/height_image.h), stb_image underneath: any bytes
// must give a grayscale image within the size limit or a message naming the file, never a crash
// or an allocation sized by a damaged header.
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <string>

#include "assets/height_image.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  rm3d::GrayImage img;
  std::string err;
  if (!rm3d::decodeGrayImage(data, size, "fuzz.png", img, err)) {
    if (err.rfind("'fuzz.png'", 0) != 0 || !img.values.empty()) std::abort();
    return 0;
  }
  if (img.width < 1 || img.height < 1 || img.width > rm3d::kMaxImageSide ||
      img.height > rm3d::kMaxImageSide || img.values.size() != size_t(img.width) * size_t(img.height))
    std::abort();
  for (float v : img.values)
    if (!(v >= 0 && v <= 1)) std::abort();
  return 0;
}
