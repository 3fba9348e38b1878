// PhysicsWorld: resting heights (no convex margin gap), locking parts into one body, hinges.
#include "physics/physics_world.h"

#include <doctest/doctest.h>

using namespace rm3d;

namespace {

ShapeDef box(double x, double y, double z) {
  ShapeDef s;
  s.kind = ShapeKind::Box;
  s.size = Vec3(x, y, z);
  return s;
}

/// A 4 cm cube as a convex hull (8 points, 12 triangles).
ShapeDef hullCube(double h) {
  ShapeDef s;
  s.kind = ShapeKind::Hull;
  for (int i = 0; i < 8; ++i) s.points.emplace_back(i & 1 ? h : -h, i & 2 ? h : -h, i & 4 ? h : -h);
  s.triangles = {0, 2, 1, 1, 2, 3, 4, 5, 6, 5, 7, 6, 0, 1, 4, 1, 5, 4,
                 2, 6, 3, 3, 6, 7, 0, 4, 2, 2, 4, 6, 1, 3, 5, 3, 7, 5};
  return s;
}

void run(PhysicsWorld& w, double seconds) {
  for (int i = 0; i < int(seconds * 60); ++i) w.step(1.0 / 60, 4);
}

}  // namespace

TEST_CASE("a box and a hull rest on the ground at their true height (no margin gap)") {
  PhysicsWorld w(PhysicsSettings{});
  w.addGroundPlane(0.8, 0);
  PartDesc b;
  b.shapes = {box(0.04, 0.04, 0.04)};
  b.mass = 0.1;
  b.pose.pos = Vec3(0, 0, 0.1);
  const int pb = w.addPart(b);
  PartDesc h;
  h.shapes = {hullCube(0.02)};
  h.mass = 0.1;
  h.pose.pos = Vec3(0.2, 0, 0.1);
  const int ph = w.addPart(h);
  run(w, 1.0);
  CHECK(w.partPose(pb).pos.z() == doctest::Approx(0.02).epsilon(0.02));
  CHECK(std::abs(w.partPose(ph).pos.z() - 0.02) < 0.0015);  // hull margin is 1 mm, not Bullet's 40
}

TEST_CASE("locking two parts makes one rigid body that keeps their relative pose and momentum") {
  PhysicsSettings s;
  s.gravity = Vec3::Zero();
  PhysicsWorld w(s);
  PartDesc a;
  a.shapes = {box(0.1, 0.1, 0.1)};
  a.mass = 1.0;
  const int pa = w.addPart(a);
  PartDesc b = a;
  b.mass = 3.0;
  b.pose.pos = Vec3(0.1, 0, 0);
  const int pb = w.addPart(b);
  CHECK(w.bodyCount() == 2);
  w.lockParts(pa, pb);
  CHECK(w.bodyCount() == 1);
  CHECK(w.sameBody(pa, pb));
  const Pose before = w.partPose(pa).inverse() * w.partPose(pb);
  run(w, 0.5);
  const Pose after = w.partPose(pa).inverse() * w.partPose(pb);
  CHECK((after.pos - before.pos).norm() < 1e-6);
  CHECK((w.partPose(pb).pos - Vec3(0.1, 0, 0)).norm() < 1e-6);  // at rest, nothing moved
}

TEST_CASE("a hinge servo drives the child to the target, and transformParts moves rigidly") {
  PhysicsSettings s;
  s.gravity = Vec3::Zero();
  PhysicsWorld w(s);
  PartDesc a;
  a.shapes = {box(0.05, 0.05, 0.05)};
  a.mass = 0.2;
  a.owner = 0;
  const int pa = w.addPart(a);
  PartDesc b = a;
  b.shapes[0].pose.pos = Vec3(0.06, 0, 0);
  const int pb = w.addPart(b);
  HingeDesc h;
  h.partA = pa;
  h.partB = pb;
  h.frameA.pos = h.frameB.pos = Vec3(0.03, 0, 0);
  h.maxTorque = 1.0;
  h.maxSpeed = 2.0;
  const int hinge = w.addHinge(h);
  w.setMotor(hinge, MotorMode::Servo, 0.5);
  run(w, 1.0);
  CHECK(w.hingeAngle(hinge) == doctest::Approx(0.5).epsilon(0.02));
  const HingeQuality q = w.hingeQuality();
  CHECK(q.maxGap < 0.0005);
  Pose delta;
  delta.pos = Vec3(1, 2, 3);
  const Vec3 pbBefore = w.partPose(pb).pos;
  w.transformParts({pa, pb}, delta);
  CHECK((w.partPose(pb).pos - pbBefore - Vec3(1, 2, 3)).norm() < 1e-6);
  CHECK(w.hingeAngle(hinge) == doctest::Approx(0.5).epsilon(0.02));
}

TEST_CASE("unlocking splits a body into its still-locked groups, each keeping its velocity") {
  PhysicsSettings s;
  s.gravity = Vec3::Zero();
  PhysicsWorld w(s);
  PartDesc d;
  d.shapes = {box(0.1, 0.1, 0.1)};
  d.mass = 1.0;
  std::vector<int> p;
  for (int i = 0; i < 3; ++i) {
    d.pose.pos = Vec3(0.1 * i, 0, 0);
    p.push_back(w.addPart(d));
  }
  w.lockParts(p[0], p[1]);
  w.lockParts(p[1], p[2]);
  CHECK(w.bodyCount() == 1);
  CHECK(w.lockedGroup(p[0]) == std::vector<int>{p[0], p[1], p[2]});
  CHECK(w.lockedGroup(p[2], p[1], p[2]) == std::vector<int>{p[2]});
  w.setPartVelocity(p[0], Vec3(0.5, 0, 0));
  w.unlockParts(p[1], p[2]);
  CHECK(w.bodyCount() == 2);
  CHECK(w.sameBody(p[0], p[1]));
  CHECK_FALSE(w.sameBody(p[1], p[2]));
  CHECK(w.partLinearVelocity(p[2]).x() == doctest::Approx(0.5));
  CHECK(w.partLinearVelocity(p[0]).x() == doctest::Approx(0.5));
}

TEST_CASE("internalLoad of a part resting on another reads its weight") {
  PhysicsWorld w(PhysicsSettings{});
  w.addGroundPlane(0.8, 0);
  PartDesc d;
  d.shapes = {box(0.1, 0.1, 0.1)};
  d.mass = 2.0;
  d.pose.pos = Vec3(0, 0, 0.05);
  const int bottom = w.addPart(d);
  d.mass = 0.5;
  d.pose.pos = Vec3(0, 0, 0.15);
  const int top = w.addPart(d);
  w.lockParts(bottom, top);
  w.setLoadTracking(true);
  run(w, 0.5);
  // The bottom part holds the top one up: the force on `top` from the rest is its weight, upward.
  const Wrench load = w.internalLoad({top}, Vec3(0, 0, 0.1));
  CHECK(load.force.z() == doctest::Approx(0.5 * 9.81).epsilon(0.02));
  CHECK(std::abs(load.force.x()) + std::abs(load.force.y()) < 0.05);
  CHECK(load.torque.norm() < 0.05);
}
