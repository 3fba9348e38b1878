// The Bullet side of cloth (physics/cloth.h): each cloth one btSoftBody in the physics world,
// colliding with bodies through Bullet's signed-distance test of every node against each
// body's shape (fCollision::SDF_RS). Only physics/*.cpp include this header.
#pragma once

#include <BulletSoftBody/btSoftBody.h>
#include <BulletSoftBody/btSoftRigidDynamicsWorld.h>

#include <cstdint>
#include <memory>
#include <vector>

#include "physics/cloth.h"

namespace rm3d {

/// Broadphase group of cloth; the ground plane leaves it out of its mask (see ClothSystem).
constexpr int kClothFilterGroup = 1 << 7;

class ClothSystem {
 public:
  /// Sets up the world's soft-body state (fine signed-distance grid, gravity).
  ClothSystem(btSoftRigidDynamicsWorld& world, const btVector3& gravity);
  ~ClothSystem();
  ClothSystem(const ClothSystem&) = delete;
  ClothSystem& operator=(const ClothSystem&) = delete;

  int add(const ClothDesc& desc);
  void setGravity(const btVector3& g);
  /// The ground plane z = 0 with this friction. Soft bodies cannot use Bullet's infinite plane
  /// (its triangles are cached where the cloth first touched it), so cloth meets a large static
  /// box standing in for it, seen by cloth only.
  void setGround(double friction);
  /// Before a step of substeps `h` seconds long: the sheets' iterations and damping, so that they
  /// stretch and settle per second as at the reference substep whatever the world's substeps.
  void setSubstep(double h);
  /// Once per step: drops signed-distance cells no node has used for a while.
  void afterStep();

  int count() const { return int(m_cloths.size()); }
  const btSoftBody& body(int c) const { return *m_cloths[size_t(c)].body; }
  void setPinned(int c, int node, bool pinned);
  bool pinned(int c, int node) const;

 private:
  struct Cloth {
    btSoftBody* body = nullptr;
    std::vector<btScalar> mass;  ///< each node's mass when free
  };
  btSoftRigidDynamicsWorld& m_world;
  std::vector<Cloth> m_cloths;
  std::unique_ptr<btCollisionShape> m_groundShape;
  std::unique_ptr<btCollisionObject> m_ground;
  int64_t m_steps = 0;
  double m_substep = 0;  ///< the substep the sheets' settings are for (0: not set yet)
};

}  // namespace rm3d
