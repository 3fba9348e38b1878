// One particle engine for fluids and debris (Macklin et al., "Unified Particle Physics for
// Real-Time Applications", 2014): position-based fluids (Macklin and Mueller, "Position Based
// Fluids", 2013: a density constraint per particle with its lambda, the s_corr tensile term and
// XSPH viscosity) and granular debris (contact constraints between particles with static and
// kinetic friction), coupled both ways with the rigid bodies (physics/particle_colliders.h).
//
// Data-oriented: positions and velocities are structures of float arrays, re-sorted by grid cell
// every step (a counting sort, then each array gathered into the new order), so a particle's
// neighbours sit near it in memory. Neighbour lists are built once per step from a 27-cell scan
// (cells are as wide as the kernel, or for debris 1.2 spacings, and a row of three cells along x
// is one contiguous range). A particle gathers from its neighbours and writes only its own slot:
// fluid passes are Jacobi style, in blocks of particles; debris passes go up columns of cells,
// Gauss-Seidel within a column, columns of one colour (never touching) side by side. Either way
// any number of threads gives bit-identical results; the one sum over particles (the push on
// each body) is made on one thread in particle order.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "core/function_ref.h"
#include "core/types.h"
#include "physics/particle_colliders.h"

namespace rm3d {

struct ParticleDef {
  enum class Kind : uint8_t { Fluid, Debris };
  Kind kind = Kind::Fluid;
  Vec3 min = Vec3::Zero(), max = Vec3::Zero();  ///< box filled with particles on a cubic lattice
  double spacing = 0.02;                        ///< m between particles (also their diameter)
  double density = 1000;                        ///< kg/m^3 (the fluid's, or the grains' bulk)
  double viscosity = 0.01;                      ///< fluid: XSPH coefficient (0..1)
  double tension = 0.01;                        ///< fluid: s_corr strength (tensile instability)
  double friction = 0.0;                        ///< static friction against bodies and (debris) grains
  double kineticFriction = -1;                  ///< < 0: 0.8 x friction
  double damping = 0.0;                         ///< share of velocity lost per second
  int iterations = 3;                           ///< solver iterations per step
  /// Substeps a step is split into (at most `iterations`, which they share); 0: fluids one per
  /// iteration, debris one (Macklin et al. 2019, "Small Steps in Physics Simulation").
  int substeps = 0;
  double kernel = 1.8;  ///< fluid: kernel radius in spacings
  double maxSpeed = 4;  ///< m/s: at dt 1/60, 6.7 cm a step (no tunnelling through 10 cm walls)

  /// Particles the box holds (may be huge: check before building).
  double particleCount() const;
};

/// The push of the particles on one body over the last step, as a force and a torque about its
/// centre of mass (world frame): apply them during the next step.
struct BodyPush {
  int part = -1;
  Vec3 force = Vec3::Zero(), torque = Vec3::Zero(), com = Vec3::Zero();
};

class ParticleSystem {
 public:
  /// Runs fn(b) for b in [0, n), possibly in parallel (null: in order on this thread).
  using ParallelFor = std::function<void(int n, FunctionRef<void(int)> fn)>;
  /// Where the time of the last step went, ms.
  struct Times {
    double sort = 0, neighbours = 0, solve = 0, finish = 0;
  };

  explicit ParticleSystem(const ParticleDef& def);
  const ParticleDef& def() const { return m_def; }
  const char* kindName() const { return m_def.kind == ParticleDef::Kind::Fluid ? "fluid" : "debris"; }

  /// One step of dt under gravity, against the bodies in `colliders` (their poses now); the
  /// bodies' share of the push is in pushes() afterwards.
  void step(double dt, const Vec3& gravity, const ColliderSet& colliders, const ParallelFor& parallel);
  const std::vector<BodyPush>& pushes() const { return m_pushes; }
  const Times& times() const { return m_times; }

  int count() const { return m_n; }
  float radius() const { return m_radius; }
  double particleMass() const { return m_mass; }
  const std::vector<float>& x() const { return m_px; }
  const std::vector<float>& y() const { return m_py; }
  const std::vector<float>& z() const { return m_pz; }
  /// Bounding box of the particles (NaN ones left out); both zero when none are finite.
  void bounds(Vec3& lo, Vec3& hi) const;
  Vec3 meanVelocity() const;
  int nanCount() const;
  /// FNV-1a of the positions' and velocities' bits (determinism tests).
  uint64_t stateHash() const;

 private:
  void fill();
  /// Debris: the grains moved off their lattice at random, the overlaps relaxed (n: sites per axis).
  void disorder(const int n[3]);
  /// Velocities get gravity (kept with `store`), positions are predicted dt ahead.
  void predict(float dt, const Vec3& gravity, const ParallelFor& parallel, bool store);
  /// Velocities from the motion over dt; the new positions become the start (p <- q).
  void advance(float dt, const ParallelFor& parallel);
  void sortByCell(const ParallelFor& parallel);
  void buildNeighbours(const ParallelFor& parallel);
  void markColliderCells(const ColliderSet& colliders, float dt);
  void fluidIteration(const ColliderSet& colliders, const ParallelFor& parallel);
  /// Debris: the order granularPass solves the grains in, from this step's grid.
  void orderGrains();
  /// Debris: one pass over the contacts between grains (non-penetration, friction), in columns
  /// of cells from the bottom up, Gauss-Seidel on the grains already solved in the pass and
  /// Jacobi (a mean weighted by depth) on the others; each grain writes only its own slot.
  /// `stabilising` (Macklin et al. 2014, 4.4): on the start-of-step positions, without friction,
  /// moving the predicted positions alike, so resolving an overlap gives no velocity.
  void granularPass(bool stabilising, const ParallelFor& parallel);
  /// Debris: grains that would move slower than a threshold stay put (particle sleeping).
  void sleep(float dt, const ParallelFor& parallel);
  /// Adds the corrections (none with `move` false) and resolves contacts; for fluids also the
  /// bodies' share of each particle's density (wall terms) at the new positions. `last`: the
  /// step's last pass, which also guards the fixed shapes (particles/particle_walls.h).
  void applyAndCollide(float dt, bool move, bool last, const ColliderSet& colliders,
                       const ParallelFor& parallel);
  /// The share of a particle's kernel sum a solid half-space at signed distance sd makes up,
  /// and its derivative along the normal (in units of the rest density).
  void wallTerm(float sd, float& share, float& slope) const;
  void finish(float dt, const ParallelFor& parallel);
  void reducePushes(float dt, int substeps, const ColliderSet& colliders);
  /// fn(begin, end) over blocks of particles, in parallel when given.
  template <class F>
  void forBlocks(const ParallelFor& parallel, F&& fn) const;

  ParticleDef m_def;
  int m_n = 0;
  float m_radius = 0.01f, m_spacing = 0.02f, m_h = 0.036f;
  double m_mass = 0;
  bool m_ground = false;   ///< this step's colliders have the ground
  float m_dt = 1.0f / 60;  ///< this step's
  float m_minLoad = 0;     ///< debris: |g| dt^2, the least overlap friction is limited by
  int m_substeps = 1;
  float m_omega = 2;  ///< over-relaxation of the lambdas
  // Fluid constants (set once): poly6 and spiky factors, rest kernel sum, relaxation, s_corr.
  float m_poly6 = 0, m_spiky = 0, m_restSum = 1, m_eps = 0, m_scorrK = 0, m_scorrW = 1;

  // Particle state, sorted by cell: positions, velocities, ids (order of creation).
  std::vector<float> m_px, m_py, m_pz, m_vx, m_vy, m_vz;
  std::vector<uint32_t> m_id;
  // Per step: predicted positions, corrections, lambdas, cell of each particle.
  std::vector<float> m_qx, m_qy, m_qz, m_dx, m_dy, m_dz, m_lambda;
  std::vector<uint32_t> m_cell;
  // Sorting scratch.
  std::vector<float> m_tmp;
  std::vector<uint32_t> m_tmpId, m_perm, m_cellStart, m_cursor;
  // The grid of this step.
  float m_origin[3] = {0, 0, 0}, m_cellSize = 1, m_invCell = 1;
  int m_dims[3] = {1, 1, 1};
  // Neighbour lists: up to m_stride per particle (fluid: kMaxNeighbours; debris, whose lists
  // reach just past the touching distance: kMaxGrainNeighbours).
  static constexpr int kMaxNeighbours = 48, kMaxGrainNeighbours = 16;
  int m_stride = kMaxNeighbours;
  std::vector<uint32_t> m_nbr;
  std::vector<uint8_t> m_nbrCount;
  // Debris: the solve order (orderGrains): the grains, each column's first entry in it (colour by
  // colour, and one past the last), each colour's first column; and the grains' working copy.
  std::vector<uint32_t> m_order, m_orderColumn;
  int m_orderColour[5] = {0, 0, 0, 0, 0};
  struct Grain {
    float x, y, z;
    uint32_t done;  ///< solved in this pass
    float px, py, pz, pad;
  };
  std::vector<Grain> m_grains;
  // Colliders near each cell (cell c's are m_cellShapes[m_cellShapeStart[c] ...
  // m_cellShapeStart[c + 1]], in the set's order), and the push on up to two bodies per particle.
  std::vector<uint32_t> m_cellShapeStart;
  std::vector<int32_t> m_cellShapes;
  std::vector<int> m_shapeCells;     // each shape's cells: lo x, y, z, hi x, y, z
  std::vector<int32_t> m_touchBody;  // 2 per particle, -1: none
  std::vector<float> m_touch;        // 2 x 6 per particle: push (3), moment about the com (3)
  // Fluid boundaries: the bodies' share of each particle's density and its gradient (all the
  // bodies', then per touched body), and the share against distance (a table over [0, h]).
  std::vector<float> m_wallS, m_wallGx, m_wallGy, m_wallGz, m_slotG;
  static constexpr int kWallTable = 64;
  float m_wallShare[kWallTable + 1] = {}, m_wallSlope[kWallTable + 1] = {};
  std::vector<BodyPush> m_pushes;
  std::vector<float> m_blockLo, m_blockHi;
  Times m_times;
};

}  // namespace rm3d
