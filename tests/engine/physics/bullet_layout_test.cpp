// physics/bullet_layout.h names the right fields of Bullet's bodies and manifolds: each place
// holds what Bullet's public calls set or return (a wrong place would leave every fetch ahead
// fetching the wrong line).
#include "physics/bullet_layout.h"

#include <doctest/doctest.h>

#include "physics/fused_passes_check.h"

TEST_CASE("bullet_layout: every place holds the field it names") {
  CHECK(rm3d::bullet_layout::mismatch() == "");
}

// SolverWorld runs Bullet's seven passes over the bodies as two where one substep is stepped; a
// world stepped that way and one stepped through Bullet's separate passes end in the same bits
// (gravity, damping, a force cleared each step, a body falling asleep).
TEST_CASE("solver world: the fused passes over the bodies give Bullet's bits") {
  CHECK(rm3d::fusedPassesMismatch() == "");
}
