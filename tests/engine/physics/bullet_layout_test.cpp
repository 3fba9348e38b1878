// physics/bullet_layout.h names the right fields of Bullet's bodies and manifolds: each place
// holds what Bullet's public calls set or return (a wrong place would leave every fetch ahead
// fetching the wrong line).
#include "physics/bullet_layout.h"

#include <doctest/doctest.h>

TEST_CASE("bullet_layout: every place holds the field it names") {
  CHECK(rm3d::bullet_layout::mismatch() == "");
}
