// A picture of a world in two parts: the layout, fixed once the world is built (meshes, which
// item sits on which link, dock or body, colours, names), and the state, one per step (poses,
// joint angles, dock and fault flags, range-sensor hits, clock). buildSnapshot puts the two
// together; the live renderer and `rm3d replay` (which reads both from a recording) draw through
// it, so a replayed frame is the live one to the pixel. Frames: z up, metres.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "core/types.h"
#include "io/snapshot.h"

namespace rm3d {

class World;

struct SceneLayout {
  enum class Kind : uint8_t { Link, Dock, Body };
  /// One drawn item: a shape on a module link, a dock face, or a body (obstacle) shape.
  struct Item {
    Kind kind = Kind::Link;
    int owner = 0;  ///< module index (Link, Dock) or body index (Body)
    int link = 0;   ///< the module link it sits on (Link, Dock)
    int dock = -1;  ///< the dock index in the module (Dock)
    Pose local;     ///< item frame in its link's (or body's) frame
    Eigen::Vector3f scale = Eigen::Vector3f::Ones();
    std::array<float, 4> color{0.8f, 0.8f, 0.8f, 1.0f};
    int mesh = 0;
  };
  struct Range {  ///< a range sensor, drawn as a line to its hit
    int module = 0, link = 0;
    Vec3 pos = Vec3::Zero(), dir = Vec3::UnitX();
    double minRange = 0, maxRange = 1;
  };
  struct ModuleInfo {
    std::string name, type;
    int id = 0, rootLink = 0;
    int firstLink = 0, firstJoint = 0, firstDock = 0;  ///< offsets into SceneState's arrays
    std::vector<std::string> joints, docks;
    int links = 0;
  };
  /// world.camera{...}, by value (follow: module index or -1).
  struct CameraDef {
    std::optional<Vec3> eye, target;
    int follow = -1;
    double fovDeg = 45;
  };

  std::vector<RenderMesh> meshes;
  std::vector<Item> items;
  std::vector<Range> ranges;
  std::vector<ModuleInfo> modules;
  std::vector<double> bodyRadius;  ///< per body: radius of a sphere around its shape (framing)
  struct Cloth {                   ///< a cloth, drawn as a two-sided mesh whose vertices are its nodes now
    int nodes = 0;
    std::vector<uint32_t> triangles;
    std::array<float, 4> color{0.8f, 0.3f, 0.25f, 1};
  };
  std::vector<Cloth> cloths;
  struct Particles {  ///< a particle system (fluid, debris), drawn as equal spheres
    int count = 0;
    float radius = 0.01f;
    std::array<float, 4> color{0.2f, 0.45f, 0.9f, 1};
  };
  std::vector<Particles> particles;
  bool ground = true;
  double dt = 1.0 / 60;
  CameraDef camera;
  int linkCount = 0, jointCount = 0, dockCount = 0;
  /// Per item: for a Dock item, how far its link's shapes reach from the dock's centre across
  /// the face (the larger of both ways, along the dock frame's y and z), for the engaged mark;
  /// zero for other items. Derived from the meshes and items by completeLayout (not recorded).
  std::vector<Eigen::Vector2f> dockReach;
};

/// Fills the layout's derived parts (dockReach) from its meshes and items: sceneLayout does, and
/// so does reading a recording.
void completeLayout(SceneLayout& layout);
/// The two bars of an engaged dock's mark (kDockMark): transform of the dock item's box mesh.
std::array<Eigen::Matrix4f, 2> dockMarkTransforms(const SceneLayout& layout, size_t item,
                                                  const Pose& linkPose);

struct SceneState {
  double time = 0;
  int64_t steps = 0;
  int faults = 0;
  std::vector<Pose> links;        ///< every module's links, module after module
  std::vector<double> joints;     ///< joint angles, rad, module after module
  std::vector<uint8_t> docks;     ///< per dock: bit 0 enabled, bit 1 engaged
  std::vector<uint8_t> faulted;   ///< per module: 1 when faulted
  std::vector<double> rangeHits;  ///< per range sensor: distance past minRange to the hit, or -1
  std::vector<Pose> bodies;       ///< per body (obstacle)
  /// Per particle set (fluid, debris): the box holding its spheres (centres grown by the
  /// radius), framed by the automatic camera like a body. Empty boxes are skipped.
  std::vector<Eigen::AlignedBox3d> particleBounds;
  std::vector<Eigen::Vector3f> clothNodes;  ///< every cloth's nodes, cloth after cloth
  std::vector<Eigen::Vector3f> particles;   ///< every particle system's centres, system after system
};

/// Colours buildSnapshot gives by state (linear RGBA): a faulted module's links; a dock face
/// disabled, engaged or free.
inline constexpr std::array<float, 4> kFaultColor{0.85f, 0.1f, 0.1f, 1.0f};
inline constexpr std::array<float, 4> kDockDisabledColor{0.9f, 0.15f, 0.1f, 1},
    kDockEngagedColor{0.2f, 0.8f, 0.3f, 1}, kDockFreeColor{0.55f, 0.55f, 0.6f, 1};
/// The mark of an engaged dock (so a docked pair is told from two modules that only touch): a
/// cross of two bars on the dock item's mesh (a box), centred `shift` along the dock's outward
/// normal from the dock item (just inside the face) and `depth` deep along it; one bar along the
/// face's y axis, one along its z axis, each reaching `overhang` past the link's own shapes
/// (SceneLayout::dockReach) so it shows beyond the module's outline from any side, and
/// `thickness` times the face's size wide. Both docks of a mated pair draw one, so the cross
/// straddles the seam.
struct DockMarkShape {
  float shift, depth, overhang, thickness;
};
inline constexpr DockMarkShape kDockMark{-0.0055f, 0.012f, 0.012f, 0.3f};

SceneLayout sceneLayout(const World& world);
/// Fills `out` (its arrays keep their capacity: no allocation after the first call).
void captureState(const World& world, const SceneLayout& layout, SceneState& out);
Snapshot buildSnapshot(const SceneLayout& layout, const SceneState& state);
/// --labels: every module's name above its root link.
void addModuleLabels(const SceneLayout& layout, const SceneState& state, Snapshot& snap);

/// The camera for a picture of `now`. world.camera{...} wins where given; otherwise the camera
/// frames the scene at the start (every module, every body under 10 m across: obstacles,
/// static ones too, and every particle set) and keeps that frame while the modules stay inside it; a module
/// leaving it widens the frame just enough, continuously (no re-framing from frame to frame).
Camera sceneCamera(const SceneLayout& layout, const SceneState& start, const SceneState& now);

}  // namespace rm3d
