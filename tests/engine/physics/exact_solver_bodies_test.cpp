// ExactSolver::convertBodies makes the solver bodies Bullet 3.24's convertBodies makes: the same
// ids, the same fields, bit for bit, for moving, kinematic and fixed bodies, with the gyroscopic
// impulse of a spinning body, and for a list that names a body twice (where it takes Bullet's loop).
#include <doctest/doctest.h>

#include "physics/exact_solver_check.h"

TEST_CASE("exact solver: its solver bodies are Bullet's, bit for bit") {
  CHECK(rm3d::solverBodiesMismatch() == "");
}

// ExactSolver::convertContacts, with friction by patches, leaves Bullet's per-point friction rows
// unmade (and its rolling rows): the contact rows, friction directions, pools' sizes and the
// solver bodies after the warm start are still Bullet's, bit for bit.
TEST_CASE("exact solver: its contact rows are Bullet's, bit for bit") {
  CHECK(rm3d::contactRowsMismatch() == "");
}
