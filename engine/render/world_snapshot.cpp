// Snapshot building from a live World: its layout and its state now (render/scene_state.h).
#include "render/world_snapshot.h"

#include "render/scene_state.h"
#include "world/world.h"

namespace rm3d {

Snapshot buildSnapshot(const World& w) {
  const SceneLayout layout = sceneLayout(w);
  SceneState state;
  captureState(w, layout, state);
  Snapshot snap = buildSnapshot(layout, state);
  // Particle systems: one set of spheres each, blue fluid, sand-coloured debris.
  for (const auto& ps : w.particleSystems()) {
    RenderSpheres s;
    s.radius = ps->radius();
    s.color = ps->def().kind == ParticleDef::Kind::Fluid ? std::array<float, 4>{0.2f, 0.45f, 0.9f, 1.0f}
                                                         : std::array<float, 4>{0.76f, 0.62f, 0.38f, 1.0f};
    s.centers.resize(size_t(ps->count()));
    for (size_t i = 0; i < s.centers.size(); ++i)
      s.centers[i] = Eigen::Vector3f(ps->x()[i], ps->y()[i], ps->z()[i]);
    snap.spheres.push_back(std::move(s));
  }
  return snap;
}

Camera worldCamera(const World& w) {
  const SceneLayout layout = sceneLayout(w);
  SceneState state;
  captureState(w, layout, state);
  return sceneCamera(layout, state, state);
}

}  // namespace rm3d
