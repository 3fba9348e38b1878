// Cloth: a rectangular sheet of point masses joined by springs, simulated by Bullet's soft bodies
// behind PhysicsWorld::addCloth. This header says what a cloth is (ClothDesc) and how its grid
// is numbered and triangulated; it includes no Bullet header.
//
// Nodes form an nx x ny grid: node (ix, iy) has index iy * nx + ix; ix runs from corner 1 to
// corner 2, iy from corner 1 to corner 4. So corner 1 is node 0, corner 2 node nx - 1, corner 3
// node nx * ny - 1 and corner 4 node (ny - 1) * nx.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "core/types.h"

namespace rm3d {

struct ClothDesc {
  std::array<Vec3, 4> corners;  ///< world frame, in order around the edge
  int nx = 2, ny = 2;           ///< nodes along corner 1 -> 2 and corner 1 -> 4 (each at least 2)
  double mass = 0.1;            ///< kg, the whole sheet (shared by area)
  double stiffness = 0.9;       ///< (0, 1]: how hard the springs hold their rest length
  double friction = 0.5;        ///< with bodies (times the body's own friction)
  double thickness = 0.005;     ///< m: how far from a surface the cloth stops
  std::vector<int> pinned;      ///< node indices held fixed in space
};

/// Limits on the grid (per side and in all), so one call cannot eat the machine.
constexpr int kClothMaxSide = 256;
constexpr int kClothMaxNodes = 65536;

/// Index of the node at corner k (0..3) of an nx x ny grid.
inline int clothCornerNode(int nx, int ny, int k) {
  const int at[4] = {0, nx - 1, nx * ny - 1, (ny - 1) * nx};
  return at[k & 3];
}

/// The grid's triangles, three node indices each, two per cell; the same triangles and order
/// the simulation uses (cells split along alternating diagonals).
std::vector<uint32_t> clothTriangles(int nx, int ny);

}  // namespace rm3d
