// Contacts between a polyhedron (box or convex hull) and a static plane, all found in one step.
//
// Bullet's convex-plane algorithm adds one point per step (the deepest vertex) and keeps the
// points of earlier steps in the manifold; a box needs four steps to stand on four corners, and a
// sliding or rocking body keeps losing points as they drift beyond the breaking threshold. With
// one substep per step that showed: a box sliding down a slope ran 3.8% slow and sank 15 mm, and
// a SuperBot's bracket hulls came to rest 5 mm high and tilted 3 degrees against its plates. This
// algorithm takes every vertex within the breaking threshold of the plane each time, reduces them
// to the four that span the largest area (the deepest first), and gives them to the manifold,
// which keeps each matching point's impulse for warm starting. A vertex closing on the plane
// faster than that also counts as far out as it closes in 1.5 steps (a speculative contact): a
// body falling more than the threshold in a step otherwise went into the ground before it had one.
//
// Beside it, Bullet's algorithms for a module's compound bodies and boxes with the box tests they
// repeat for nothing left out (the same contacts, bit for bit; plane_contacts_check.h): a compound
// against a plane runs each child's plane step without testing the child's box against the
// plane's; a compound (or two boxes) whose box lies apart from the other's skips its children (or
// the separating-axis test).
#pragma once

#include <BulletCollision/CollisionDispatch/btCollisionCreateFunc.h>
#include <BulletCollision/CollisionDispatch/btCollisionDispatcher.h>

namespace rm3d {

/// Registers the algorithm for boxes and convex hulls against static planes (both orders), and
/// Bullet's compound and box-box algorithms with their needless box tests left out
/// (plane_contacts.cpp: CompoundPlaneAlgorithm, CompoundNearAlgorithm, BoxBoxNearAlgorithm).
/// `funcs` must outlive the dispatcher's use of them.
struct PlaneContactFuncs {
  /// Makes one of those algorithms (`make`, set by registerWith) for a pair, in either order.
  struct Func : btCollisionAlgorithmCreateFunc {
    btCollisionAlgorithm* (*make)(btCollisionAlgorithmConstructionInfo&, const btCollisionObjectWrapper*,
                                  const btCollisionObjectWrapper*, bool swapped) = nullptr;
    btCollisionAlgorithm* CreateCollisionAlgorithm(btCollisionAlgorithmConstructionInfo& ci,
                                                   const btCollisionObjectWrapper* body0,
                                                   const btCollisionObjectWrapper* body1) override {
      return make(ci, body0, body1, m_swapped);
    }
  };
  Func plain, swapped;                  ///< box or hull against a plane
  Func compoundPlain, compoundSwapped;  ///< compound against a plane
  Func nearPlain, nearSwapped;          ///< compound against a convex shape or a compound
  Func boxBox;                          ///< box against box
  void registerWith(btCollisionDispatcher& dispatcher);
};

}  // namespace rm3d
