// A module type as data (MuJoCo's mjModel idea): links, joints, docks, sensors, read from
// assets/modules/<type>.lua. All poses are in the module frame at zero joint angles, which is
// also every link's own frame, so a joint's pivot and axis mean the same thing in both links.
#pragma once

#include <array>
#include <optional>
#include <string>
#include <vector>

#include "physics/shape_def.h"

namespace rm3d {

struct LinkDef {
  std::string name;
  double mass = 0.1;
  std::vector<ShapeDef> shapes;  ///< what the link is made of: drawn, and its mass properties
  /// Separate collision geometry (the `collision` list of a module-type file), carrying the mass
  /// properties of `shapes` (massFrom); empty: `shapes` collide.
  std::vector<ShapeDef> collision;
  std::array<float, 4> color{0.8f, 0.8f, 0.8f, 1.0f};
  double friction = 1.0;
  /// m: the lever arm of the link's resistance to rolling and spinning on what it rests on (a
  /// contact resists a turn up to rolling_friction x mu x its normal force; 0: none).
  double rollingFriction = 0.0;

  /// What physics builds the link from.
  const std::vector<ShapeDef>& collisionShapes() const { return collision.empty() ? shapes : collision; }
};

struct JointDef {
  std::string name;
  int parent = -1, child = -1;  ///< link indices; angle = rotation of child about axis
  Vec3 pivot = Vec3::Zero();
  Vec3 axis = Vec3::UnitZ();  ///< unit
  bool limited = true;        ///< false: continuous
  double lower = -kPi / 2, upper = kPi / 2;
  double maxTorque = 1.0, maxSpeed = 1.0;
  double servoGain = 20.0;
  double servoStiffness = 0;  ///< N m/rad a held servo gives under load (0: rigid)
};

enum class Gender { None, Male, Female };

struct DockDef {
  std::string name;
  int link = -1;
  Vec3 pos = Vec3::Zero();      ///< face centre
  Vec3 normal = Vec3::UnitX();  ///< outward, unit
  Vec3 up = Vec3::UnitZ();      ///< reference direction in the face, unit, normal to `normal`
  Gender gender = Gender::None;
  double size = 0.034;  ///< face side, m
  int symmetry = 4;     ///< ways the face can mate about its normal (4: square)
  // Run-time docking: a free, enabled dock attracts a compatible one within `captureRadius`
  // whose face looks back within `captureAngle`, and latches when the faces are within
  // `latchDistance` and `latchAngle` (normals and one of the `symmetry` orientations).
  double captureRadius = 0.03;   ///< m
  double captureAngle = 0.5236;  ///< rad (30 deg)
  double latchDistance = 0.004;  ///< m
  double latchAngle = 0.0873;    ///< rad (5 deg)
  /// How a captured dock is drawn in: a capture joint (a constraint of bounded speed, force and
  /// torque between the two dock links, solved with the contacts; the default) or a magnet (a
  /// force `pull` at each face, and torques pull x size). Pairs where either dock says magnet,
  /// and every pair on the "pgs" solver, use the magnet.
  enum class Capture : uint8_t { Joint, Magnet };
  Capture capture = Capture::Joint;
  double captureSpeed = 0.05;     ///< m/s: the joint closes the faces at most this fast ...
  double captureTurnSpeed = 1.0;  ///< rad/s: ... and turns them at most this fast
  double captureForce = 20.0;     ///< N: the most force the joint exerts
  double captureTorque = 1.0;     ///< N m: the most torque the joint exerts
  double captureTime = 3.0;       ///< s: a capture not latched after this is reported as stalled
  double pull = 2.0;              ///< N, the magnet's pull inside the capture radius
  double strength = 100.0;        ///< N: a connection breaks above this transmitted force
  double strengthTorque = 10.0;   ///< N m: ... or above this transmitted torque
  Pose frame;                     ///< derived: the dock frame in its link (docking/dock_frame.h)
};

/// Dock settings a world puts over its module types' (world.docks{} for every module spawned
/// after it, world.spawn's `docks` for one module): the fields that are set win.
struct DockSettings {
  std::optional<DockDef::Capture> capture;
  std::optional<double> captureRadius, captureAngle, latchDistance, latchAngle, captureSpeed,
      captureTurnSpeed, captureForce, captureTorque, captureTime, pull, strength, strengthTorque;

  bool empty() const { return key().empty(); }
  /// These settings over `d`.
  void applyTo(DockDef& d) const;
  /// `o`'s set fields over these.
  void overlay(const DockSettings& o);
  /// A text naming exactly the fields set and their values ("" when none).
  std::string key() const;

  /// The numeric settings: their key in Lua, where each lives here and in a DockDef, and the
  /// range world.docks accepts.
  struct Field {
    const char* key;
    std::optional<double> DockSettings::*setting;
    double DockDef::*value;
    double lo, hi;
    const char* unit;
  };
  static const Field kFields[12];
};

enum class SensorKind { Accelerometer, Gyro, Orientation, Position, Range, Contact };

/// A sensor the type carries (joint:<name> and dock:<name> exist for every joint and dock).
struct SensorDef {
  SensorKind kind = SensorKind::Accelerometer;
  std::string name;          ///< what behaviours read: "accelerometer", "range:front", "contact:chassis"
  int link = 0;              ///< the link it sits on (its frame is the sensor frame)
  Vec3 pos = Vec3::Zero();   ///< range: ray origin in the link frame
  Vec3 dir = Vec3::UnitX();  ///< range: ray direction (unit)
  double minRange = 0.02, maxRange = 2.0;  ///< range, m
};

struct ModuleTypeDef {
  std::string name;
  std::string file;
  int rootLink = 0;  ///< the link whose frame is the module frame
  std::vector<LinkDef> links;
  std::vector<JointDef> joints;
  std::vector<DockDef> docks;
  std::vector<SensorDef> sensors;
  double dockReach = 0;           ///< derived: farthest a dock's capture zone gets from the root origin
  bool hasAccelerometer = false;  ///< derived
  bool hasContact = false;        ///< derived

  int findLink(const std::string& n) const;
  int findJoint(const std::string& n) const;
  int findDock(const std::string& n) const;
  int findSensor(const std::string& n) const;
  double mass() const;
};

const char* genderName(Gender g);

}  // namespace rm3d
