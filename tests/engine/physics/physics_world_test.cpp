// PhysicsWorld: resting heights (no convex margin gap), locking parts into one body, hinges.
#include "physics/physics_world.h"

#include <doctest/doctest.h>

#include "test_world.h"

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

namespace {

/// A horizontal chain of `n` 0.1 m boxes (0.2 kg) hinged about y, the first hinged to a static
/// base; every servo holds 0. Returns the hinge ids.
std::vector<int> cantileverChain(PhysicsWorld& w, int n, double torque, double stiffness = 0) {
  PartDesc base;
  base.shapes = {box(0.05, 0.05, 0.05)};
  base.mass = 0;
  base.pose.pos = Vec3(0, 0, 1);
  int prev = w.addPart(base);
  std::vector<int> hinges;
  for (int i = 0; i < n; ++i) {
    PartDesc p;
    p.shapes = {box(0.1, 0.04, 0.04)};
    p.mass = 0.2;
    p.owner = i;
    p.pose.pos = Vec3(0.075 + 0.1 * i, 0, 1);
    const int part = w.addPart(p);
    HingeDesc h;
    h.partA = prev;
    h.partB = part;
    // Pivot 0.025 m ahead of the previous part's centre (the base) or 0.05 m (a link); axis y.
    h.frameA.pos = Vec3(i == 0 ? 0.025 : 0.05, 0, 0);
    h.frameA.rot = Quat(Eigen::AngleAxisd(-kPi / 2, Vec3::UnitX()));
    h.frameB.pos = Vec3(-0.05, 0, 0);
    h.frameB.rot = h.frameA.rot;
    h.maxTorque = torque;
    h.maxSpeed = 3;
    h.servoStiffness = stiffness;
    const int id = w.addHinge(h);
    w.setMotor(id, MotorMode::Servo, 0);
    hinges.push_back(id);
    prev = part;
  }
  return hinges;
}

}  // namespace

TEST_CASE(
    "exact solver: a servo chain holds its load at the statically exact torque, and gives way above its "
    "rating") {
  // Load on the first hinge: links at 0.05, 0.15, 0.25 m from it, 0.2 kg each.
  const double g = 9.81, need = 0.2 * g * (0.05 + 0.15 + 0.25);  // 0.883 N m
  for (const double rating : {1.5, 0.6}) {
    PhysicsSettings s;
    s.solver = SolverKind::Exact;
    PhysicsWorld w(s);
    const std::vector<int> hinges = cantileverChain(w, 3, rating);
    for (int i = 0; i < 60; ++i) w.step(1.0 / 60, 1);
    if (rating > need) {
      CHECK(std::abs(w.hingeAngle(hinges[0])) < 1e-3);
      // Angles are right-handed about the axis (-y here): holding the chain up pushes B about +y.
      CHECK(std::abs(w.hingeTorque(hinges[0])) == doctest::Approx(need).epsilon(0.01));
      CHECK_FALSE(w.hingeSaturated(hinges[0]));
      CHECK(w.hingeQuality().maxGap < 1e-5);
      CHECK(w.hingeQuality().maxAngle < 1e-4);
    } else {
      CHECK(std::abs(w.hingeAngle(hinges[0])) > 0.2);  // gave way
      CHECK(w.hingeSaturated(hinges[0]));
      CHECK(std::abs(w.hingeTorque(hinges[0])) == doctest::Approx(rating).epsilon(0.001));
      CHECK(w.hingeQuality().maxGap < 1e-4);
    }
  }
}

TEST_CASE("exact solver: a servo with a stiffness yields torque / stiffness under a held load") {
  const double g = 9.81, need = 0.2 * g * (0.05 + 0.15 + 0.25);  // 0.883 N m on the first hinge
  for (const double k : {50.0, 300.0}) {
    PhysicsSettings s;
    s.solver = SolverKind::Exact;
    PhysicsWorld w(s);
    const std::vector<int> hinges = cantileverChain(w, 3, 2.5, k);
    for (int i = 0; i < 240; ++i) w.step(1.0 / 60, 1);
    // The links tip a little (the angle's sign is about -y), so the load is a hair smaller.
    CHECK(std::abs(w.hingeTorque(hinges[0])) == doctest::Approx(need).epsilon(0.02));
    CHECK(std::abs(w.hingeAngle(hinges[0])) == doctest::Approx(need / k).epsilon(0.03));
    CHECK(w.hingeQuality().maxGap < 1e-5);
  }
}

TEST_CASE("exact solver: a servo with a stiffness gives its full rating only while its law asks for it") {
  // A link held level (0.098 N m of gravity) is lifted 0.1 rad by a servo rated 0.0985 N m
  // (stiffness 20 N m/rad, gain 20/s): it saturates, rises, and leaves its rating near the top.
  // The servo's law asks for (command - speed) / (compliance x dt), the command gain x error: it
  // asks for the whole rating only while the joint lags its command by at least gain x rating /
  // stiffness (0.0985 rad/s). A saturated row that came back only once the joint ran past the
  // command itself held full torque one step too long (0.0941 rad/s behind the command: 96% of
  // the rating asked for).
  PhysicsSettings s;
  s.solver = SolverKind::Exact;
  PhysicsWorld w(s);
  const double rating = 0.0985, stiffness = 20, gain = 20, dt = 1.0 / 60;
  const int hinge = cantileverChain(w, 1, rating, stiffness)[0];
  for (int i = 0; i < 60; ++i) w.step(dt, 1);
  CHECK(!w.hingeSaturated(hinge));
  w.setMotor(hinge, MotorMode::Servo, -0.1);
  int saturated = 0;
  double closest = 1;  // the least lag behind the command of a step that ended saturated
  for (int i = 0; i < 120; ++i) {
    const double err = -0.1 - w.hingeAngle(hinge);
    const double command =
        std::clamp(std::clamp(gain * err, -3.0, 3.0), -std::abs(err) / dt, std::abs(err) / dt);
    w.step(dt, 1);
    if (!w.hingeSaturated(hinge)) continue;
    ++saturated;
    closest = std::min(closest, std::abs(command - w.hingeVelocity(hinge)));
  }
  MESSAGE("lift: " << saturated << " steps at the rating, the least lag behind the command " << closest
                   << " rad/s");
  CHECK(saturated > 10);
  CHECK(closest >= gain * rating / stiffness - 1e-6);
  CHECK(w.hingeAngle(hinge) == doctest::Approx(-0.1 + 0.098 * std::cos(0.1) / stiffness).epsilon(0.02));
}

namespace {

/// Four 0.1 m links around a square (link i along +x turned 90 deg x i about z), hinged corner to
/// corner about z, motors off: a planar four-bar. With `grounded`, link 0 is static; `closed`: the
/// fourth hinge closes the loop (else an open chain); `oneOwner`: the links never collide;
/// `motor`: the hinges' torque, speed and servo stiffness. Hinge k joins link k to link k + 1.
std::vector<int> fourBar(PhysicsWorld& w, bool grounded, bool closed = true, bool oneOwner = false,
                         const HingeDesc& motor = HingeDesc()) {
  std::vector<int> parts;
  for (int i = 0; i < 4; ++i) {
    PartDesc p;
    p.shapes = {box(0.1, 0.02, 0.02)};
    p.mass = grounded && i == 0 ? 0.0 : 0.1;
    p.owner = oneOwner ? 0 : i;
    p.pose.rot = Quat(Eigen::AngleAxisd(kPi / 2 * i, Vec3::UnitZ()));
    p.pose.pos = Vec3(0, 0, 1) + p.pose.rot * Vec3(0, -0.05, 0);
    parts.push_back(w.addPart(p));
  }
  for (int i = 0; i < (closed ? 4 : 3); ++i) {
    HingeDesc h;
    h.partA = parts[size_t(i)];
    h.partB = parts[size_t((i + 1) % 4)];
    h.frameA.pos = Vec3(0.05, 0, 0);
    h.frameB.pos = Vec3(-0.05, 0, 0);
    h.frameB.rot = Quat(Eigen::AngleAxisd(-kPi / 2, Vec3::UnitZ()));
    h.limited = false;
    h.maxTorque = motor.maxTorque;
    h.maxSpeed = motor.maxSpeed;
    h.servoStiffness = motor.servoStiffness;
    w.setMotor(w.addHinge(h), MotorMode::Off, 0);
  }
  return parts;
}

}  // namespace

TEST_CASE("exact solver: a four-bar anchored twice holds every hinge exactly, under either solver") {
  PhysicsSettings s;
  s.solver = SolverKind::Exact;
  s.gravity = Vec3::Zero();
  PhysicsWorld w(s);
  // Link 0 is the static ground link, so two hinges anchor the loop to the static world.
  const std::vector<int> parts = fourBar(w, true);
  CHECK(w.hingeQuality().maxGap < 1e-6);
  // Pull the coupler sideways: the square shears into a parallelogram, every hinge loaded.
  auto pull = [&] {
    for (int i = 0; i < 30; ++i) {
      w.addForce(parts[2], Vec3(2, 0, 0), w.partPose(parts[2]).pos);
      w.step(1.0 / 60, 1);
    }
  };
  pull();
  const double sheared = w.partPose(parts[2]).pos.x();
  CHECK(sheared > 0.02);
  CHECK(w.hingeQuality().maxGap < 1e-5);
  // Switching to the pgs solver rebuilds every hinge as a Bullet hinge; the four-bar still holds.
  PhysicsSettings p = w.settings();
  p.solver = SolverKind::Pgs;
  w.configure(p);
  pull();
  CHECK(w.partPose(parts[2]).pos.x() > sheared);
  CHECK(w.hingeQuality().maxGap < 5e-3);
}

/// Pulls link 2 along x and pushes link 0 off centre, down and out of the plane, for 90 steps of
/// 1/60 s at one substep (the square shears and tumbles); returns the largest hinge gap and
/// axis angle over every step, and leaves in `corner` the most the corner angle between links 0
/// and 1 moved from its square 90 deg.
std::pair<double, double> shearAndTumble(PhysicsWorld& w, const std::vector<int>& parts, double force,
                                         double& corner) {
  double gap = 0, angle = 0;
  corner = 0;
  for (int i = 0; i < 90; ++i) {
    w.addForce(parts[2], force * Vec3(2, 0, 0), w.partPose(parts[2]).pos);
    w.addForce(parts[0], force * Vec3(0, -1, 0.5), w.partPose(parts[0]).pos + Vec3(0.05, 0, 0));
    w.step(1.0 / 60, 1);
    gap = std::max(gap, w.hingeQuality().maxGap);
    angle = std::max(angle, w.hingeQuality().maxAngle);
    const double a =
        angleBetween(w.partPose(parts[0]).rot * Vec3::UnitX(), w.partPose(parts[1]).rot * Vec3::UnitX());
    corner = std::max(corner, std::abs(a - kPi / 2));
  }
  return {gap, angle};
}

TEST_CASE("exact solver: a free ring of four links closes its loop exactly (Schur complement)") {
  PhysicsSettings s;
  s.solver = SolverKind::Exact;
  s.gravity = Vec3::Zero();
  PhysicsWorld w(s);
  // No static link: the four hinges form a loop of moving bodies, one of which the tree leaves
  // out. The square shears through its flat-folded poses and tumbles. Measured: 2.6e-6 m and
  // 1.2e-5 rad at worst; with one stabilisation pass at the substep's start rows, the ring tore
  // (2 m) and at half these forces its hinges opened 1.3 mm / 3.9 deg. (At twice these forces it
  // still comes apart: folding flat at speed, the loop's rows lose rank.)
  double corner = 0;
  const auto [gap, angle] = shearAndTumble(w, fourBar(w, false), 0.5, corner);
  MESSAGE("ring: largest gap " << gap << " m, axis angle " << angle << " rad");
  CHECK(corner > 0.05);
  CHECK(gap < 1e-5);
  CHECK(angle < 1e-4);
}

TEST_CASE("exact solver: a ring whose servos reach their rating leaves every hinge moving as one") {
  // The free ring above with its servos on, each commanded 0.4 rad the same way round: a closed
  // four-bar cannot turn every corner one way, so the motors push against each other through the
  // loop and reach their rating. A tree row fixed at its rating in a bounded solve was set on its
  // joint's two bodies alone, and the loop's solve then factored the tree again without solving
  // it: its other hinges were left pulling apart until the next substep's solve (pivots
  // separating at up to 0.72 m/s here; with it, 3.7e-5).
  PhysicsSettings s;
  s.solver = SolverKind::Exact;
  s.gravity = Vec3::Zero();
  PhysicsWorld w(s);
  HingeDesc motor;
  motor.maxTorque = 0.05;
  motor.maxSpeed = 3;
  motor.servoStiffness = 300;
  const std::vector<int> parts = fourBar(w, false, true, true, motor);
  for (int k = 0; k < 4; ++k) w.setMotor(k, MotorMode::Servo, 0.4);
  // The pivots' relative velocity in the ring's plane (the out-of-plane rows of a planar loop
  // repeat each other, and the solver damps them).
  auto pivotSlip = [&](int k) {  // (hinge k joins link k's +x end to link k + 1)
    const int pa = parts[size_t(k)], pb = parts[size_t((k + 1) % 4)];
    const Pose a = w.partPose(pa), b = w.partPose(pb);
    const Vec3 p = a.pos + a.rot * Vec3(0.05, 0, 0);
    const Vec3 va = w.partLinearVelocity(pa) + w.partAngularVelocity(pa).cross(p - a.pos);
    const Vec3 vb = w.partLinearVelocity(pb) + w.partAngularVelocity(pb).cross(p - b.pos);
    const Vec3 d = va - vb;
    return std::hypot(d.x(), d.y());
  };
  double slip = 0;
  int saturated = 0;
  for (int i = 0; i < 60; ++i) {
    w.step(1.0 / 60, 1);
    for (int k = 0; k < 4; ++k) saturated += w.hingeSaturated(k), slip = std::max(slip, pivotSlip(k));
  }
  MESSAGE("ring of servos: " << saturated << " saturated hinge-steps, largest pivot slip " << slip << " m/s");
  CHECK(saturated > 0);
  CHECK(slip < 1e-4);
  CHECK(w.hingeQuality().maxGap < 1e-5);
}

TEST_CASE(
    "exact solver: a free chain tumbling at one substep keeps its hinges (stabilised at the new poses)") {
  // Bodies integrated one by one open a hinge by about h^2 x joint speed x tumbling rate (BCH);
  // projected once with the rows of the substep's start, a 4-link chain kept tilt errors of 0.04
  // rad and its hinges opened by up to 5 mm / 5 deg. Projected again at the corrected poses:
  // 1.7e-6 m and 1.6e-5 rad.
  PhysicsSettings s;
  s.solver = SolverKind::Exact;
  s.gravity = Vec3::Zero();
  PhysicsWorld w(s);
  double corner = 0;
  const auto [gap, angle] = shearAndTumble(w, fourBar(w, false, false), 1.0, corner);
  MESSAGE("chain: largest gap " << gap << " m, axis angle " << angle << " rad, " << w.newtonPasses()
                                << " passes at the corrected poses, " << w.chordPasses()
                                << " with the first's factor");
  CHECK(corner > 0.05);
  CHECK(gap < 1e-5);
  CHECK(angle < 1e-4);
  // Tumbling, the first pass's rate is too poor for a second with its factor: 1.1 mm / 0.029 rad
  // when every later pass took it.
  CHECK(w.newtonPasses() > 0);
}

TEST_CASE("a box slides down a slope at g (sin - mu cos) within 2% at one substep on both solvers") {
  // Bullet's convex-plane contact gave one new point per step: at one substep the box ran 3.8%
  // slow and sank 15 mm (engine/physics/plane_contacts.h). Gravity tilted 30 degrees, mu 0.3.
  for (const char* solver : {"pgs", "exact"}) {
    const std::string script =
        std::string("world.set{solver = '") + solver + R"(', substeps = 1, solver_iterations = 10,
  gravity = {9.81 * math.sin(math.rad(30)), 0, -9.81 * math.cos(math.rad(30))}}
world.ground{friction = 1.0}
local box = world.box{size = {0.1, 0.1, 0.1}, at = {0, 0, 0.05}, mass = 1, friction = 0.3}
local expected = 9.81 * (math.sin(math.rad(30)) - 0.3 * math.cos(math.rad(30)))
local v1
world.at(0.5, function() v1 = box:velocity().x end)
world.at(1.5, function()
  local a = box:velocity().x - v1
  expect(math.abs(a - expected) < 0.02 * expected, string.format("acceleration %.4f, expected %.4f", a, expected))
  expect(math.abs(box:position().z - 0.05) < 0.001, string.format("height %.4f m", box:position().z))
end)
)";
    auto w = test::makeWorld(script);
    test::stepFor(*w, 1.6);
    CHECK_MESSAGE(w->failures().empty(), (std::string(solver) + ": " + test::failureText(*w)));
  }
}

TEST_CASE("a box dropped onto the ground lands on it, not in it (speculative plane contacts)") {
  // Contacts with the plane were made only within the breaking threshold (1.7 mm for this box):
  // falling 52 mm a step (3.1 m/s after 0.5 m, at 1/60 s) it went 17.8 mm into the ground before
  // it had one (19.2 mm from 2 m). Vertices closing on the plane now make contacts as far out as
  // they close in 1.5 steps, and the solver lets a contact still apart close by its distance:
  // measured 0.00 and 0.01 mm, and no bounce, at the defaults and on both solvers.
  for (const char* solver : {"exact", "pgs"})
    for (double height : {0.5, 2.0}) {
      const std::string script =
          std::string("world.set{solver = '") + solver + "'}\nlocal height = " + std::to_string(height) + R"(
world.ground{}
local box = world.box{size = {0.1, 0.1, 0.1}, at = {0, 0, 0.05 + height}, mass = 1}
local lowest, highest, landed = math.huge, -math.huge, nil
world.on_step(function(t)
  local z = box:position().z
  lowest = math.min(lowest, z)
  if not landed and z < 0.06 then landed = t end
  if landed and t > landed then highest = math.max(highest, z) end
end)
world.at(1.5, function()
  expect(landed ~= nil, "the box landed")
  expect(lowest > 0.05 - 0.001, string.format("lowest 1 mm into the ground at most: %.2f mm", (0.05 - lowest) * 1000))
  expect(highest < 0.05 + 0.001, string.format("no bounce: %.2f mm above rest", (highest - 0.05) * 1000))
end)
)";
      auto w = test::makeWorld(script);
      test::stepFor(*w, 1.6);
      CHECK_MESSAGE(w->failures().empty(), std::string(solver)
                                               << " from " << height << " m: " << test::failureText(*w));
    }
}

TEST_CASE("exact solver: a free chain turning in zero gravity keeps its kinetic energy") {
  // Four 0.1 m links hinged end to end, motors off, links not colliding with each other, kicked
  // out of the plane and left to turn and flail for 10 s at the defaults' substep (1/120 s; links
  // up to 20 rad/s). Nothing dissipates, so the kinetic energy stays. Measured: -0.7% .. +0.3%;
  // with the hinge rows aiming at J v = 0 (no centripetal target) it fell by 57%.
  PhysicsSettings s;
  s.solver = SolverKind::Exact;
  s.gravity = Vec3::Zero();
  PhysicsWorld w(s);
  const std::vector<int> parts = fourBar(w, false, false, true);
  for (int i = 0; i < 10; ++i) {
    w.addForce(parts[0], Vec3(0, -0.3, 0.15), w.partPose(parts[0]).pos + Vec3(0.05, 0, 0));
    w.addForce(parts[3], Vec3(0.15, 0, -0.3), w.partPose(parts[3]).pos);
    w.step(1.0 / 60, 2);
  }
  auto energy = [&] {
    double e = 0;
    const Vec3 inertia = 0.1 / 12 * Vec3(0.02 * 0.02 * 2, 0.1 * 0.1 + 0.02 * 0.02, 0.1 * 0.1 + 0.02 * 0.02);
    for (int p : parts) {
      const Vec3 wl = w.partPose(p).rot.conjugate() * w.partAngularVelocity(p);
      e += 0.5 * 0.1 * w.partLinearVelocity(p).squaredNorm() + 0.5 * wl.dot(inertia.cwiseProduct(wl));
    }
    return e;
  };
  const double start = energy();
  double lo = start, hi = start, fastest = 0;
  for (int i = 0; i < 600; ++i) {
    w.step(1.0 / 60, 2);
    lo = std::min(lo, energy());
    hi = std::max(hi, energy());
    for (int p : parts) fastest = std::max(fastest, w.partAngularVelocity(p).norm());
  }
  MESSAGE("kinetic energy " << start << " J, then " << lo << " .. " << hi << " J over 10 s; links up to "
                            << fastest << " rad/s");
  CHECK(fastest > 10);
  CHECK(lo > 0.98 * start);
  CHECK(hi < 1.02 * start);
  CHECK(w.hingeQuality().maxGap < 1e-5);
}

TEST_CASE("bodies of the same part share one compound shape wherever they stand, made and let go with them") {
  PhysicsWorld w{PhysicsSettings{}};
  w.addGroundPlane(0.8, 0);
  PartDesc d;  // two boxes, its centre of mass off its origin: a compound
  d.shapes = {box(0.1, 0.06, 0.04), box(0.04, 0.04, 0.04)};
  d.shapes[1].pose.pos = Vec3(0.03, 0, 0.04);
  d.mass = 0.3;
  std::vector<int> parts;
  for (int i = 0; i < 20; ++i) {  // at places and headings whose roundings differ
    d.pose.pos = Vec3(0.35 * (i % 5) - 0.7, 0.3 * (i / 5) + 0.1, 0.0201);
    d.pose.rot = Quat(Eigen::AngleAxisd(0.3 * i, Vec3::UnitZ()));
    parts.push_back(w.addPart(d));
  }
  CHECK(w.bodyCount() == 20);
  CHECK(w.compoundCount() == 1);
  PartDesc other = d;  // the small box on the other side
  other.shapes[1].pose.pos = Vec3(-0.03, 0, 0.04);
  other.pose.pos = Vec3(0, -0.5, 0.0201);
  w.addPart(other);
  CHECK(w.compoundCount() == 2);
  w.lockParts(parts[0], parts[1]);  // one body of two parts: its own compound
  CHECK(w.bodyCount() == 20);
  CHECK(w.compoundCount() == 3);
  w.unlockParts(parts[0], parts[1]);  // that one let go; the two share the first again
  CHECK(w.bodyCount() == 21);
  CHECK(w.compoundCount() == 2);
  run(w, 1.0);
  for (int p : parts) CHECK(std::abs(w.partPose(p).pos.z() - 0.02) < 0.0005);  // each rests on its big box
}

TEST_CASE("contact readings are the last step's touches, read after the step or after a merge of bodies") {
  // Two boxes side by side on the ground and one in the air: the touches are those of the step's
  // end, whenever a sensor reads them, and a merge of the two bodies after the step (a dock
  // latching) leaves them as they were. A step with nobody reading makes them anew.
  auto make = [](PhysicsWorld& w, int(&p)[3]) {
    w.addGroundPlane(0.8, 0);
    PartDesc d;
    d.shapes = {box(0.04, 0.04, 0.04)};
    d.mass = 0.1;
    for (int i = 0; i < 3; ++i) {
      d.pose.pos = Vec3(0.04 * i, 0, i == 2 ? 0.5 : 0.02);
      p[i] = w.addPart(d);
    }
    w.setContactTracking(true);
  };
  PhysicsWorld w(PhysicsSettings{});
  int p[3];
  make(w, p);
  for (int i = 0; i < 10; ++i) w.step(1.0 / 60, 1);
  CHECK(w.partTouching(p[0]));
  CHECK(w.partTouching(p[1]));
  CHECK_FALSE(w.partTouching(p[2]));  // falling, 0.4 m up
  CHECK_FALSE(w.partTouching(99));    // no such part

  PhysicsWorld merged(PhysicsSettings{});
  int q[3];
  make(merged, q);
  for (int i = 0; i < 10; ++i) merged.step(1.0 / 60, 1);
  merged.lockParts(q[0], q[1]);  // their bodies (and manifolds) replaced by one, before any reading
  CHECK(merged.partTouching(q[0]));
  CHECK(merged.partTouching(q[1]));
  CHECK_FALSE(merged.partTouching(q[2]));
  // Unread steps, then the one in the air lands: the readings follow.
  for (int i = 0; i < 40; ++i) merged.step(1.0 / 60, 1);
  CHECK(merged.partTouching(q[2]));
}
