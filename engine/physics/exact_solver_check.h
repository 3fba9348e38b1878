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

}  // namespace rm3d
