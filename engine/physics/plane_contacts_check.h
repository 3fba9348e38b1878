// A check that the compound algorithms of physics/plane_contacts.cpp give Bullet's bits, for the
// unit tests (which do not see Bullet's headers).
#pragma once

#include <string>

namespace rm3d {

/// The same scene stepped in two Bullet worlds, one with Bullet's algorithms for every pair with a
/// compound and for box against box, one with PlaneContactFuncs' (CompoundPlaneAlgorithm,
/// CompoundNearAlgorithm, BoxBoxNearAlgorithm): compounds (without box trees, as PhysicsWorld makes
/// them) resting, tumbling and sliding on a plane, one passing near another (their boxes apart, then
/// meeting), a box and a hull against them, and a box sliding up to another. What happened, and
/// the first difference (a body's pose or velocity, a manifold's count, a contact point's
/// position, impulse or child index) after any step, empty if none.
struct CompoundContactsCheck {
  int steps = 0;
  int contacts = 0;         ///< contact points, summed over the steps
  int compoundTouches = 0;  ///< manifolds with points between two compounds, summed over the steps
  int nearSkips = 0;        ///< steps' compound pairs whose boxes lay apart (CompoundNearAlgorithm's way)
  int boxTouches = 0;       ///< manifolds with points between two boxes, summed over the steps
  int boxSkips = 0;         ///< steps' box pairs whose boxes lay apart (BoxBoxNearAlgorithm's way)
  /// Pairs of the broadphase (summed over the steps) whose algorithm was one of these: a compound
  /// against the plane, a compound near a shape or compound, a box near a box.
  int planeTaken = 0, nearTaken = 0, boxTaken = 0;
  std::string mismatch;
};
CompoundContactsCheck checkCompoundContacts(int steps);

}  // namespace rm3d
