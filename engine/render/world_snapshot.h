// Turns the state of a World into a render Snapshot (meshes, coloured items, overlay) and
// chooses a camera. Reads the world, never changes it.
#pragma once

#include "render/snapshot.h"

namespace rm3d {

class World;

Snapshot buildSnapshot(const World& world);
/// The world's camera (world.camera{...}); without one, frames every module from the front left.
Camera worldCamera(const World& world);

}  // namespace rm3d
