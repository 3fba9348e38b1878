// Snapshot building from a live World: its layout and its state now (io/scene_state.h).
#include "io/world_snapshot.h"

#include "io/scene_state.h"
#include "world/world.h"

namespace rm3d {

Snapshot buildSnapshot(const World& w) {
  const SceneLayout layout = sceneLayout(w);
  SceneState state;
  captureState(w, layout, state);
  return buildSnapshot(layout, state);
}

Camera worldCamera(const World& w) {
  const SceneLayout layout = sceneLayout(w);
  SceneState state;
  captureState(w, layout, state);
  return sceneCamera(layout, state, state);
}

}  // namespace rm3d
