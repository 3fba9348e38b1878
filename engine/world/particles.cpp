// World: fluids and debris (particles/particle_system.h), stepped after the bodies each step and
// pushing back on them during the next.
#include <cmath>

#include "core/error.h"
#include "world/behaviour_pool.h"
#include "world/budget.h"
#include "world/world.h"

namespace rm3d {

int World::addParticles(const ParticleDef& def) {
  ensurePhysics();
  if (m_started) throw InputError("particles are added while the world script runs, before the first step");
  double total = def.particleCount();
  for (const auto& p : m_particles) total += p->count();
  if (!(def.particleCount() >= 1))
    throw InputError("the box holds no particle at this spacing (each side must be at least one spacing)");
  if (!(total <= kMaxParticles)) {
    char buf[160];
    std::snprintf(buf, sizeof buf,
                  "too many particles: %.0f in this world (at most %.0f; use a larger spacing)", total,
                  kMaxParticles);
    throw InputError(buf);
  }
  chargeBudget(def.particleCount() * budget::kParticle,
               std::to_string((long long)def.particleCount()) + " particles");
  m_particles.push_back(std::make_unique<ParticleSystem>(def));
  return int(m_particles.size()) - 1;
}

void World::stepParticles() {
  if (m_particles.empty()) return;
  m_physics->collectColliders(m_colliders);
  ParticleSystem::ParallelFor parallel;
  if (m_pool->threads() > 1)
    parallel = [pool = m_pool.get()](int n, FunctionRef<void(int)> fn) { pool->run(n, fn, 1); };
  for (const auto& ps : m_particles) {
    ps->step(m_settings.dt, m_settings.gravity, m_colliders, parallel);
    for (const BodyPush& p : ps->pushes()) {
      if (!p.force.allFinite() || !p.torque.allFinite()) continue;
      m_physics->addForce(p.part, p.force, p.com);
      m_physics->addTorque(p.part, p.torque);
    }
  }
}

}  // namespace rm3d
