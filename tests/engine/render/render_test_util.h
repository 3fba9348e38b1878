// Small helpers shared by the offscreen rendering tests: a box mesh and reading a pixel.
#pragma once

#include <cstdint>

#include "render/offscreen_renderer.h"

namespace rm3d::test {

/// Axis-aligned box mesh with the given half extents, faces counter-clockwise from outside.
inline RenderMesh makeBox(float hx, float hy, float hz) {
  RenderMesh m;
  for (int i = 0; i < 8; ++i) m.vertices.emplace_back(i & 1 ? hx : -hx, i & 2 ? hy : -hy, i & 4 ? hz : -hz);
  m.indices = {0, 2, 3, 0, 3, 1, 4, 5, 7, 4, 7, 6, 0, 1, 5, 0, 5, 4,
               2, 6, 7, 2, 7, 3, 0, 4, 6, 0, 6, 2, 1, 3, 7, 1, 7, 5};
  return m;
}

struct Rgb {
  int r, g, b;
};

/// The last drawn frame's pixel at column x, row y from the top.
inline Rgb pixel(const OffscreenRenderer& r, int x, int y) {
  const uint8_t* p = r.rgba().data() + (size_t(y) * size_t(r.width()) + size_t(x)) * 4;
  return {p[0], p[1], p[2]};
}

}  // namespace rm3d::test
