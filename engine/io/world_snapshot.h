// Turns the state of a World into a render Snapshot (meshes, coloured items, overlay) and
// chooses a camera. Reads the world, never changes it.
#pragma once

#include "io/snapshot.h"

namespace rm3d {

class World;

Snapshot buildSnapshot(const World& world);
/// The world's camera (world.camera{...}); without one, frames every module and body as they are
/// now (sceneCamera with the state now as the start). Runs keep their start: io/scene_state.h.
Camera worldCamera(const World& world);

}  // namespace rm3d
