// ExactSolver::convertBodies makes the solver bodies Bullet 3.24's convertBodies makes: the same
// ids, the same fields, bit for bit, for moving, kinematic and fixed bodies, with the gyroscopic
// impulse of a spinning body, and for a list that names a body twice (where it takes Bullet's loop).
#include <doctest/doctest.h>

#include "physics/exact_solver_check.h"

TEST_CASE("exact solver: its solver bodies are Bullet's, bit for bit") {
  CHECK(rm3d::solverBodiesMismatch() == "");
}
