// Picking: which drawn item a ray from the camera hits first. Works on the Snapshot the renderer
// draws (item transform maps the mesh frame to the world), so a click selects what is on screen.
// Plain Eigen: no GL here.
#pragma once

#include <vector>

#include "io/snapshot.h"
#include "render/view_math.h"

namespace rm3d {

struct PickHit {
  int item = -1;       ///< index into Snapshot::items, -1: nothing (sky or ground)
  float distance = 0;  ///< along the ray, metres
};

/// Prepared once per snapshot (mesh bounds, inverse item transforms), then asked for many rays.
class Picker {
 public:
  explicit Picker(const Snapshot& s);
  /// The nearest item whose triangles the ray crosses (each item's mesh bounds, transformed into
  /// the item's frame, cull the rest first).
  PickHit pick(const Ray& ray) const;

 private:
  struct ItemData {
    Eigen::Matrix4f worldToMesh;
    bool valid = false;
  };
  const Snapshot& m_snapshot;
  std::vector<Eigen::AlignedBox3f> m_meshBounds;
  std::vector<ItemData> m_items;
};

}  // namespace rm3d
