// The compound and box-box algorithms of physics/plane_contacts.cpp against Bullet's own (the comparison runs
// in the physics library, physics/plane_contacts_check.h): every body's pose and velocity and every
// contact point the same bits after every step.
#include <doctest/doctest.h>

#include "physics/plane_contacts_check.h"

TEST_CASE(
    "compounds against planes, convex shapes and compounds: the same bits as Bullet's compound algorithms") {
  const rm3d::CompoundContactsCheck c = rm3d::checkCompoundContacts(240);
  CHECK(c.mismatch == "");
  CHECK(c.steps == 240);
  // The scene did what it is for: contacts every step on average, compounds touching compounds
  // and boxes touching boxes, and such pairs whose boxes lay apart.
  CHECK(c.contacts > 240);
  CHECK(c.compoundTouches > 0);
  CHECK(c.nearSkips > 0);
  CHECK(c.boxTouches > 0);
  CHECK(c.boxSkips > 0);
  // And the pairs went through these algorithms, not Bullet's: 5 compounds on the plane every step.
  CHECK(c.planeTaken == 5 * 240);
  CHECK(c.nearTaken > 0);
  CHECK(c.boxTaken > 0);
}
