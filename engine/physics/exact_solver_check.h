// A check that ExactSolver makes its solver bodies as Bullet does, for the unit tests (which do
// not see Bullet's headers).
#pragma once

#include <string>

namespace rm3d {

/// Empty when ExactSolver::convertBodies and Bullet 3.24's convertBodies make the same solver
/// bodies from the same lists (moving bodies spinning with forces and torques, one with the
/// gyroscopic impulse in world axes, a fixed and a kinematic body, a body listed twice): the same
/// ids and every field the same bits; else what differed first.
std::string solverBodiesMismatch();

/// Empty when ExactSolver::convertContacts (friction by patches) makes the contact rows Bullet
/// 3.24's convertContacts makes (every field the same bits), as many friction rows (all at 0),
/// the same friction directions at the points and the same solver bodies after the rows' warm
/// start: a sliding body on the ground (a point beyond the processing threshold), a body at rest,
/// a contact between the bodies with rolling friction, one between two static bodies; else what
/// differed first.
std::string contactRowsMismatch();

}  // namespace rm3d
