// The only door to Bullet. Everything else speaks in parts, hinges and poses.
//
// A *part* is one rigid piece the rest of the engine knows about: a module link or an obstacle.
// Parts locked together (docked links) are merged into one Bullet rigid body with a compound
// shape, so a dock is exact and costs the solver nothing. A *hinge* joins two parts with a
// motorised revolute joint (position servo or velocity drive, both bounded by the joint's
// torque and speed).
#pragma once

#include <functional>
#include <memory>
#include <vector>

#include "core/function_ref.h"
#include "core/types.h"
#include "physics/cloth.h"
#include "physics/particle_colliders.h"
#include "physics/shape_def.h"

namespace rm3d {

/// How joints are solved. Exact: each cluster's hinges by a direct linear-time solve, motors at
/// their true articulated inertia (engine/physics/exact_solver.h). Pgs: Bullet's
/// sequential impulses over every row (the first versions' solver, kept for comparison).
enum class SolverKind { Exact, Pgs };
/// The solver's name in world scripts (`world.set{solver=}`), the JSON summary and `rm3d bench`.
constexpr const char* solverName(SolverKind k) {
  return k == SolverKind::Exact ? "exact" : "pgs";
}

struct PhysicsSettings {
  SolverKind solver = SolverKind::Pgs;
  Vec3 gravity = Vec3(0, 0, -9.81);
  int solverIterations = 10;  ///< sequential-impulse iterations per substep
  int jointIterations = 0;    ///< per-hinge override (0: use solverIterations)
  /// Share of a joint's position error corrected per substep. Bullet's 0.2 lets SuperBot hinges
  /// open by millimetres; 0.8 keeps them under 0.5 mm at the same cost (measured, README).
  double erp = 0.8;
  /// The exact solver factors every tree whole, also where only motor rows changed (tests: its
  /// partial factors must give the same bits).
  bool wholeFactors = false;
  /// The exact solver makes its trees afresh every substep, also where the joints and bodies are
  /// those of the last (tests: trees taken again must give the same bits).
  bool freshTrees = false;
  /// The exact solver sweeps every island in every iteration, also one whose contacts have
  /// settled (tests: a settled island must end where all iterations take it); an island whose
  /// contacts are solved on their own operator (denseIslands) is solved so either way.
  bool everyIteration = false;
  /// The exact solver solves the contacts of an island of one small tree on their own operator
  /// (physics/dense_islands.cpp); off: by the sweeps alone (tests and measurements).
  bool denseIslands = true;
  /// The most coordinates (the root's six and one a hinge) of a tree whose contacts the operator
  /// takes: 60, a chain of up to eighteen SuperBots or a tree as large (at most
  /// ExactSolver::kDenseCoordinatesMax; 16, up to three docked, and then 36, up to ten, until
  /// 2026-12-07: docs/benchmarks.md).
  int denseCoordinates = 60;
  /// The exact solver's AVX variants where the CPU has AVX; off: the SSE2 ones (tests: the same
  /// bits either way).
  bool avx = true;
  /// Every piece of a step that can go to the worker threads goes there, not only where the
  /// clock says it pays (tests: core/pace.h; the bits are the same either way).
  bool alwaysThreads = false;
  /// The exact solver's batches are each integrated and stabilised right after their solve,
  /// while their data is in the caches (SolverWorld::setFinishBatches); off: in passes over every
  /// body and tree after all of them (tests and measurements: the same bits either way).
  bool finishBatches = true;
};

struct PartDesc {
  std::vector<ShapeDef> shapes;  ///< in the part frame
  double mass = 0;               ///< 0: static
  Pose pose;                     ///< part frame in the world
  double friction = 0.8;
  double restitution = 0.0;
  /// m: the lever arm of rolling resistance (Bullet's rolling friction; 0: a ball rolls forever)
  double rollingFriction = 0.0;
  int owner = -1;  ///< module index, or -1; parts sharing an owner never collide
};

struct HingeDesc {
  int partA = -1, partB = -1;  ///< angle = rotation of B relative to A about the axis
  Pose frameA, frameB;         ///< joint frame in each part frame; z is the axis
  bool limited = true;
  double lower = -kPi / 2, upper = kPi / 2;
  double maxTorque = 1.0;   ///< N m
  double maxSpeed = 1.0;    ///< rad/s
  double servoGain = 20.0;  ///< 1/s: servo speed command per radian of error
  /// N m/rad: how far a holding servo yields under load (torque / stiffness); 0: rigid. The exact
  /// solver makes the motor row compliant; pgs's motor rows are soft by iteration already.
  double servoStiffness = 0;
};

enum class MotorMode { Off, Servo, Velocity };

/// A capture joint between two parts' dock frames (docking's capture by joint; exact solver
/// only): draws B's dock frame onto A's, turned by `mate`, at a bounded speed with a bounded
/// force and torque (engine/physics/capture_joint.cpp).
struct CaptureDesc {
  int partA = -1, partB = -1;
  Pose frameA, frameB;           ///< the dock frames in each part's frame
  Quat mate = Quat::Identity();  ///< B's dock frame wanted, relative to A's
  double speed = 0.05;           ///< m/s
  double angularSpeed = 1.0;     ///< rad/s
  double gain = 5.0;             ///< 1/s
  double force = 20.0;           ///< N
  double torque = 1.0;           ///< N m
};

/// A force and a torque (about a stated point), world frame.
struct Wrench {
  Vec3 force = Vec3::Zero();
  Vec3 torque = Vec3::Zero();
};

/// The first dynamic body found in a state no physics can recover from (divergenceScan).
struct BodyDivergence {
  enum class Kind { None, Position, Orientation, Velocity, Speed, AngularSpeed, Bounds } kind = Kind::None;
  int part = -1;        ///< the body's first part (a module link or an obstacle)
  int partsInBody = 0;  ///< more than 1: docked links merged into one body
  double value = 0;     ///< Speed: m/s; AngularSpeed: rad/s; Bounds: metres from the origin
};

struct HingeQuality {
  double maxGap = 0;    ///< metres between the two pivots
  double maxAngle = 0;  ///< radians between the two axes
};

class PhysicsWorld {
 public:
  explicit PhysicsWorld(const PhysicsSettings& settings);
  ~PhysicsWorld();
  PhysicsWorld(const PhysicsWorld&) = delete;
  PhysicsWorld& operator=(const PhysicsWorld&) = delete;

  /// Gravity and iterations may change until the first step.
  void configure(const PhysicsSettings& settings);
  void addGroundPlane(double friction, double restitution);
  int addPart(const PartDesc& desc);
  int addHinge(const HingeDesc& desc);
  /// Merges the bodies holding a and b into one rigid body (no-op if already one) and records
  /// the lock a-b.
  void lockParts(int a, int b);
  /// Removes the lock a-b; the body splits into one body per group of parts still locked
  /// together, each keeping the velocity it had as part of the whole.
  void unlockParts(int a, int b);
  /// Parts locked to `part` (directly or through others), including itself, without using the
  /// lock a-b. Deterministic order.
  std::vector<int> lockedGroup(int part, int skipA = -1, int skipB = -1) const;
  /// A force (N) at a world point on a part during the next step() (magnets, pushes).
  void addForce(int part, const Vec3& force, const Vec3& worldPoint);
  /// A torque (N m, world frame) on a part's body during the next step().
  void addTorque(int part, const Vec3& torque);
  /// Turns on what internalLoad needs: hinge reaction feedback and per-part contact forces.
  void setLoadTracking(bool on);
  /// Runs fn(i) for i in [0, n), possibly in parallel (each i on its own thread where it can).
  /// With `threads` > 1 the batches of islands are solved on `threads` solvers at once, one per
  /// task (SolverWorld::setBatchSolvers); each batch touches only its own bodies, joints and
  /// contacts, so the results do not depend on the thread count.
  /// `watch`: the threads may spin while they wait (no more threads than cores: the pool's
  /// rule, BehaviourPool::watches); then a long tree's half helper spins through its solve.
  using ForEach = std::function<void(int n, FunctionRef<void(int)> fn)>;
  void setParallel(int threads, ForEach forEach, bool watch = false);
  /// The force and torque (about `point`) that the rest of their rigid body exerted on the given
  /// parts, averaged over the last step(), from Newton-Euler on those parts: their change of
  /// momentum over the step minus the impulses of gravity, contacts and hinge reactions on them.
  Wrench internalLoad(const std::vector<int>& parts, const Vec3& point) const;
  /// Moves parts rigidly by `delta` (world frame), keeping their relative poses. For placing
  /// modules before they interact; velocities are kept.
  void transformParts(const std::vector<int>& parts, const Pose& delta);

  /// A cloth (physics/cloth.h; the desc is checked by the caller); returns its index.
  int addCloth(const ClothDesc& desc);
  int clothCount() const;
  int clothNodeCount(int cloth) const;
  Vec3 clothNode(int cloth, int node) const;  ///< world frame, m
  Vec3 clothNodeVelocity(int cloth, int node) const;
  /// A pinned node stays where it is (it keeps its place in space, not on a body).
  void setClothNodePinned(int cloth, int node, bool pinned);
  bool clothNodePinned(int cloth, int node) const;
  /// False when some node's position or velocity is NaN or infinite (one pass, no allocation).
  bool clothFinite(int cloth) const;

  /// Adds a capture joint; returns its id (ids of removed ones are reused).
  int addCapture(const CaptureDesc& desc);
  void removeCapture(int id);

  void setMotor(int hinge, MotorMode mode, double value);
  /// Starts fetching, for writing, what setMotor(hinge, ...) writes (a pass over many modules calls
  /// it a few modules ahead); no effect on any result.
  void fetchMotor(int hinge) const;
  /// Sets the linear velocity of the body holding the part (a thrown obstacle), waking it.
  void setPartVelocity(int part, const Vec3& v);
  /// True when the body holding the part is static or asleep. Obstacles (parts of no module)
  /// fall asleep once still for 2 s and wake when touched; module bodies never sleep.
  bool partSleeping(int part) const;
  /// Dynamic bodies awake now (the others cost a step nothing).
  int activeBodyCount() const;
  /// The last substep's work on the worker threads: overlapping pairs whose contacts were found
  /// there (0: one thread's loop), trees solved in two halves (ExactSolver::splitTree), bodies
  /// integrated there (SolverWorld::integrateTransforms; 0: Bullet's loop), and contact sweeps
  /// run in a split tree's two halves (ExactSolver::planHalvedSweep).
  int threadedPairs() const;
  int splitTrees() const;
  int threadedBodies() const;
  int halvedSweeps() const;
  /// Lists of the last substep (solver bodies, contact rows, sweep items, write-backs) made in two
  /// runs on a split tree's halves' threads (ExactSolver::halvedListCount).
  int halvedLists() const;
  /// Factors so far that took only the nodes whose rows changed (ExactSolver::factor).
  long partialFactors() const;
  /// Substeps whose trees the exact solvers took again from the last substep (reuseTrees).
  long reusedTrees() const;
  /// Solver batches so far, and those integrated and stabilised right after their solve
  /// (PhysicsSettings::finishBatches).
  long solvedBatches() const;
  long finishedBatches() const;
  /// Contact sweeps of islands so far, and those spared because the island had settled
  /// (ExactSolver::planSettling).
  long islandSweeps() const;
  long sparedSweeps() const;
  /// Position stabilisation passes after a cluster's first so far: with the first pass's factor
  /// (chord steps), and with rows and factor at the corrected poses (Newton steps).
  long chordPasses() const;
  long newtonPasses() const;
  /// Islands whose contacts the exact solvers solved on their own operator so far (one an island
  /// a substep; ExactSolver::denseIslandCount).
  long denseIslands() const;
  /// Advances by dt in `substeps` equal steps, updating servos before each one.
  void step(double dt, int substeps);

  Pose partPose(int part) const;
  /// Starts fetching what partPose(part) will read into the caches (a pass over many modules
  /// calls it a few modules ahead); no effect on any result.
  void fetchPartPose(int part) const;
  /// The lowest height (world z) any collision shape of these parts reaches, margins included.
  double lowestPoint(const std::vector<int>& parts) const;
  Vec3 partLinearVelocity(int part) const;
  Vec3 partAngularVelocity(int part) const;
  bool sameBody(int a, int b) const;
  /// Distance along a ray to the first body hit, ignoring bodies that hold parts of module
  /// `ignoreOwner`; negative when nothing is hit within `length`. Safe to call from several
  /// threads (Bullet's ray test is serialised inside).
  double rayCast(const Vec3& from, const Vec3& dir, double length, int ignoreOwner) const;
  /// Keeps, after every step, which parts touch something (for contact sensors).
  void setContactTracking(bool on);
  bool partTouching(int part) const;
  double hingeAngle(int hinge) const;
  double hingeVelocity(int hinge) const;
  /// Torque (N m) the hinge's motor applied during the last step, positive turning B about the
  /// axis relative to A; with a limit in contact, the motor and the limit stop together.
  double hingeTorque(int hinge) const;
  /// True when the motor delivered its rated torque during the last step (it could not hold or
  /// reach its command).
  bool hingeSaturated(int hinge) const;
  HingeQuality hingeQuality() const;
  /// One pass over Bullet's dynamic bodies (no allocation): the first whose position,
  /// orientation or velocity is NaN or infinite, whose linear or angular speed exceeds the given
  /// bound, or whose centre of mass is farther than `maxDistance` from the origin.
  BodyDivergence divergenceScan(double maxSpeed, double maxAngularSpeed, double maxDistance) const;
  /// Every body's collision shapes at their poses now, for particle systems (arrays reused).
  void collectColliders(ColliderSet& out) const;
  int partCount() const;
  double partMass(int part) const;  ///< kg (0: static)
  int bodyCount() const;
  /// The bodies' distinct compound shapes (bodies with the same children share one).
  int compoundCount() const;
  const PhysicsSettings& settings() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> m;
};

}  // namespace rm3d
