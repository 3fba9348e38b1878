// Pixel checks for the picture tests (tests/cli/html_replay_test.sh, dock_marks_test.sh).
//   image_compare count A.png R,G,B           pixels of A whose hue is that of the linear colour
//   image_compare iou A.png B.png R,G,B       the same mask in A and B: intersection over union
//   image_compare white A.png                 pixels with every channel at 250 or more (text)
//   image_compare same SHOWN.png DRAWN.png    exit 0 when they show the same: the same size, and
//                                             pixels equal to a rounding (what another CPU's
//                                             software rasteriser may change); 1 saying how not
// A pixel matches when its channels, divided by the largest, are within 0.08 of those of
// pow(colour, 1/2.2) (both renderers write colour * light with one scalar light per pixel,
// gamma-encoded, so shading keeps those ratios) and its largest channel is at least 40 (too dark
// to judge otherwise). Images of different sizes are an error (exit 2).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
#pragma GCC diagnostic ignored "-Wsign-compare"
#pragma GCC diagnostic ignored "-Wunused-function"
#define STB_IMAGE_STATIC
#define STB_IMAGE_IMPLEMENTATION
#include <stb/stb_image.h>
#pragma GCC diagnostic pop

namespace {

struct Image {
  int w = 0, h = 0;
  std::vector<unsigned char> rgba;
};

bool load(const char* path, Image& img) {
  int channels = 0;
  unsigned char* p = stbi_load(path, &img.w, &img.h, &channels, 4);
  if (!p) {
    std::fprintf(stderr, "image_compare: %s: cannot read it as an image\n", path);
    return false;
  }
  img.rgba.assign(p, p + size_t(img.w) * size_t(img.h) * 4);
  stbi_image_free(p);
  return true;
}

bool parseColour(const char* text, float hue[3]) {
  float c[3];
  char tail = 0;
  if (std::sscanf(text, "%f,%f,%f%c", &c[0], &c[1], &c[2], &tail) != 3) {
    std::fprintf(stderr, "image_compare: %s: expected a linear colour R,G,B\n", text);
    return false;
  }
  float top = 0;
  for (int i = 0; i < 3; ++i) top = std::max(top, hue[i] = std::pow(std::max(c[i], 0.0f), 1 / 2.2f));
  if (top <= 0) return false;
  for (int i = 0; i < 3; ++i) hue[i] /= top;
  return true;
}

std::vector<bool> mask(const Image& img, const float hue[3]) {
  std::vector<bool> m(size_t(img.w) * size_t(img.h));
  for (size_t i = 0; i < m.size(); ++i) {
    const unsigned char* p = &img.rgba[i * 4];
    const float top = float(std::max({p[0], p[1], p[2]}));
    if (top < 40) continue;
    bool match = true;
    for (int c = 0; c < 3; ++c) match = match && std::abs(p[c] / top - hue[c]) < 0.08f;
    m[i] = match;
  }
  return m;
}

}  // namespace

int main(int argc, char** argv) {
  const std::string mode = argc > 1 ? argv[1] : "";
  float hue[3];
  if (mode == "count" && argc == 4) {
    Image a;
    if (!load(argv[2], a) || !parseColour(argv[3], hue)) return 2;
    const std::vector<bool> m = mask(a, hue);
    std::printf("%ld\n", long(std::count(m.begin(), m.end(), true)));
    return 0;
  }
  if (mode == "white" && argc == 3) {
    Image a;
    if (!load(argv[2], a)) return 2;
    long n = 0;
    for (size_t i = 0; i < a.rgba.size(); i += 4)
      n += std::min({a.rgba[i], a.rgba[i + 1], a.rgba[i + 2]}) >= 250;
    std::printf("%ld\n", n);
    return 0;
  }
  if (mode == "iou" && argc == 5) {
    Image a, b;
    if (!load(argv[2], a) || !load(argv[3], b) || !parseColour(argv[4], hue)) return 2;
    if (a.w != b.w || a.h != b.h) {
      std::fprintf(stderr, "image_compare: %s is %dx%d, %s is %dx%d\n", argv[2], a.w, a.h, argv[3], b.w, b.h);
      return 2;
    }
    const std::vector<bool> ma = mask(a, hue), mb = mask(b, hue);
    long both = 0, either = 0, na = 0, nb = 0;
    for (size_t i = 0; i < ma.size(); ++i) {
      both += ma[i] && mb[i];
      either += ma[i] || mb[i];
      na += ma[i];
      nb += mb[i];
    }
    std::printf("%.3f %ld %ld\n", either ? double(both) / double(either) : 0.0, na, nb);
    return 0;
  }
  if (mode == "same" && argc == 4) {
    Image a, b;
    if (!load(argv[2], a) || !load(argv[3], b)) return 2;
    if (a.w != b.w || a.h != b.h) {
      std::printf("%s is %dx%d, the command drew %dx%d\n", argv[2], a.w, a.h, b.w, b.h);
      return 1;
    }
    // At most 0.5% of the pixels off by more than 24 levels, 2 levels on average.
    long off = 0;
    double sum = 0;
    const size_t n = size_t(a.w) * size_t(a.h);
    for (size_t i = 0; i < n; ++i) {
      int d = 0;
      for (int c = 0; c < 4; ++c) d = std::max(d, std::abs(int(a.rgba[i * 4 + c]) - int(b.rgba[i * 4 + c])));
      off += d > 24;
      sum += d;
    }
    const double share = double(off) / double(n), mean = sum / double(n);
    if (share > 0.005 || mean > 2) {
      std::printf(
          "%s differs from what the command draws now: %.2f%% of the pixels by more than 24 levels, "
          "%.2f levels on average\n",
          argv[2], 100 * share, mean);
      return 1;
    }
    return 0;
  }
  std::fprintf(stderr,
               "usage: image_compare count A.png R,G,B | iou A.png B.png R,G,B | white A.png | same A.png "
               "B.png\n");
  return 2;
}
