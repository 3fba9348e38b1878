// Checks loadModuleType: the shipped SuperBot (links, joints, docks, mass, docks on the link
// surfaces) and the errors for bad module-type files, which must name the file and the place.
#include "script/module_type_loader.h"

#include <doctest/doctest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "core/error.h"

namespace fs = std::filesystem;
using rm3d::Vec3;

namespace {

const std::string kRoot = RM3D_SOURCE_DIR;

/// A fresh folder under the system temp dir, removed afterwards.
struct TempDir {
  fs::path path;
  TempDir() {
    std::string tmpl = (fs::temp_directory_path() / "rm3d_mtype_test_XXXXXX").string();
    REQUIRE(mkdtemp(tmpl.data()) != nullptr);
    path = tmpl;
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path, ec);
  }
  std::string write(const std::string& name, const std::string& text) const {
    const fs::path p = path / name;
    fs::create_directories(p.parent_path());
    std::ofstream(p) << text;
    return p.string();
  }
};

bool contains(const std::string& s, const std::string& part) {
  return s.find(part) != std::string::npos;
}

/// The InputError message of loading `path`, or "" when it loads (any other exception fails).
std::string loadError(const std::string& path, const std::string& root = kRoot) {
  try {
    rm3d::loadModuleType(path, root);
  } catch (const rm3d::InputError& e) {
    return e.what();
  }
  return "";
}

/// A small valid module type with `extra` spliced into the link list, shapes, joints or docks
/// through the placeholders, so each bad case differs from a good file in one place.
std::string twoLinks(const std::string& shape = "box = {0.1, 0.1, 0.1}", const std::string& joint = "",
                     const std::string& dock = "") {
  return "return {\n"
         "  name = 'pair',\n"
         "  links = {\n"
         "    { name = 'a', mass = 1, shapes = { { " +
         shape +
         " } } },\n"
         "    { name = 'b', mass = 1, shapes = { { sphere = 0.05, at = {0.2, 0, 0} } } },\n"
         "  },\n"
         "  joints = { { name = 'j', parent = 'a', child = 'b', pivot = {0.1, 0, 0}, axis = {0, 0, 1},\n"
         "               lower = -1, upper = 1, torque = 1, speed = 1" +
         joint +
         " } },\n"
         "  docks = { { name = 'd', link = 'a', at = {0.05, 0, 0}, normal = {1, 0, 0}" +
         dock +
         " } },\n"
         "}\n";
}

/// The corners (box) or points (hull) of a shape, in its link's frame.
std::vector<Vec3> shapePoints(const rm3d::ShapeDef& s) {
  std::vector<Vec3> pts;
  if (s.kind == rm3d::ShapeKind::Box) {
    for (int i = 0; i < 8; ++i)
      pts.push_back(s.pose * Vec3((i & 1 ? 0.5 : -0.5) * s.size.x(), (i & 2 ? 0.5 : -0.5) * s.size.y(),
                                  (i & 4 ? 0.5 : -0.5) * s.size.z()));
  } else {
    for (const Vec3& p : s.points) pts.push_back(s.pose * p);
  }
  return pts;
}

}  // namespace

TEST_CASE("SuperBot loads with its links, joints, docks and mass") {
  const rm3d::ModuleTypeDef t = rm3d::loadModuleType(kRoot + "/assets/modules/superbot.lua", kRoot);
  CHECK(t.name == "superbot");
  CHECK(t.file == "assets/modules/superbot.lua");
  REQUIRE(t.links.size() == 4);
  REQUIRE(t.joints.size() == 3);
  REQUIRE(t.docks.size() == 6);
  CHECK(std::abs(t.mass() - 0.72) < 1e-9);
  CHECK(t.rootLink == t.findLink("front_inner"));

  const int fo = t.findLink("front_outer"), fi = t.findLink("front_inner");
  const int bi = t.findLink("back_inner"), bo = t.findLink("back_outer");
  REQUIRE(fo >= 0);
  REQUIRE(fi >= 0);
  REQUIRE(bi >= 0);
  REQUIRE(bo >= 0);
  CHECK(t.links[fo].shapes.size() == 3);
  CHECK(t.links[bo].shapes.size() == 3);
  for (const rm3d::ShapeDef& s : t.links[bo].shapes) {
    CHECK(s.kind == rm3d::ShapeKind::Hull);
    CHECK(contains(s.source, "assets/meshes/superbot_"));
    CHECK(s.points.size() >= 24);
  }
  CHECK(t.links[fi].shapes.at(0).kind == rm3d::ShapeKind::Box);
  CHECK(t.links[fi].shapes.at(0).size.isApprox(Vec3(0.053, 0.060, 0.060)));
  CHECK(t.links[bi].shapes.at(0).pose.pos.isApprox(Vec3(-0.0265, 0, 0)));
  CHECK(t.links[fo].color == t.links[bo].color);
  CHECK(t.links[fo].color != t.links[fi].color);

  struct Expected {
    const char* name;
    int parent, child;
    Vec3 pivot, axis;
  };
  const Expected joints[] = {{"pitch", fi, fo, Vec3(0.043, 0, 0), Vec3::UnitY()},
                             {"roll", fi, bi, Vec3::Zero(), Vec3::UnitX()},
                             {"yaw", bi, bo, Vec3(-0.043, 0, 0), Vec3::UnitZ()}};
  for (const Expected& e : joints) {
    CAPTURE(e.name);
    const int j = t.findJoint(e.name);
    REQUIRE(j >= 0);
    const rm3d::JointDef& jd = t.joints[j];
    CHECK(jd.parent == e.parent);
    CHECK(jd.child == e.child);
    CHECK((jd.pivot - e.pivot).norm() < 1e-12);
    CHECK((jd.axis - e.axis).norm() < 1e-12);
    CHECK(jd.limited);
    CHECK(jd.lower == doctest::Approx(-rm3d::kPi / 2));
    CHECK(jd.upper == doctest::Approx(rm3d::kPi / 2));
    CHECK(jd.maxTorque == 2.5);
    CHECK(jd.maxSpeed == 3);
    CHECK(jd.servoGain == 20);
  }

  struct Dock {
    const char* name;
    int link;
    Vec3 pos, normal;
  };
  const Dock docks[] = {{"front", fo, Vec3(0.095, 0, 0), Vec3::UnitX()},
                        {"back", bo, Vec3(-0.095, 0, 0), -Vec3::UnitX()},
                        {"left", fo, Vec3(0.058, 0.043, 0), Vec3::UnitY()},
                        {"right", fo, Vec3(0.058, -0.043, 0), -Vec3::UnitY()},
                        {"up", bo, Vec3(-0.058, 0, 0.043), Vec3::UnitZ()},
                        {"down", bo, Vec3(-0.058, 0, -0.043), -Vec3::UnitZ()}};
  for (const Dock& e : docks) {
    CAPTURE(e.name);
    const int d = t.findDock(e.name);
    REQUIRE(d >= 0);
    const rm3d::DockDef& dd = t.docks[d];
    CHECK(dd.link == e.link);
    CHECK((dd.pos - e.pos).norm() < 1e-12);
    CHECK((dd.normal - e.normal).norm() < 1e-12);
    CHECK(dd.gender == rm3d::Gender::None);
    CHECK(dd.size == 0.034);
    CHECK(dd.symmetry == 4);
    CHECK(std::abs(dd.up.norm() - 1) < 1e-12);
    CHECK(std::abs(dd.up.dot(dd.normal)) < 1e-12);
  }
  CHECK(t.docks[t.findDock("front")].up.isApprox(Vec3::UnitZ()));
  CHECK(t.docks[t.findDock("up")].up.isApprox(-Vec3::UnitX()));
}

TEST_CASE("SuperBot dock faces lie on the surface of their link's shapes") {
  const rm3d::ModuleTypeDef t = rm3d::loadModuleType(kRoot + "/assets/modules/superbot.lua", kRoot);
  for (const rm3d::DockDef& d : t.docks) {
    CAPTURE(d.name);
    const double face = d.pos.dot(d.normal);
    const Vec3 side = d.normal.cross(d.up);
    double linkExtent = -1e9;
    bool carried = false;  // some shape's outer face holds the whole dock square
    for (const rm3d::ShapeDef& s : t.links[d.link].shapes) {
      const std::vector<Vec3> pts = shapePoints(s);
      Vec3 lo = pts[0], hi = pts[0];
      double extent = -1e9;
      for (const Vec3& p : pts) {
        lo = lo.cwiseMin(p);
        hi = hi.cwiseMax(p);
        extent = std::max(extent, p.dot(d.normal));
      }
      linkExtent = std::max(linkExtent, extent);
      if (std::abs(extent - face) > 1e-3) continue;
      bool inside = true;
      for (double a : {-0.5, 0.5})
        for (double b : {-0.5, 0.5}) {
          const Vec3 corner = d.pos + d.size * (a * d.up + b * side);
          inside = inside && (corner.array() >= lo.array() - 1e-3).all() &&
                   (corner.array() <= hi.array() + 1e-3).all();
        }
      carried = carried || inside;
    }
    CHECK(std::abs(linkExtent - face) < 1e-3);  // nothing of the link sticks out past the face
    CHECK(carried);
  }
}

TEST_CASE("module-type details: defaults, normalising, cylinder axis, require, local meshes") {
  TempDir dir;
  dir.write("helper.lua", "return { size = 0.1 }\n");
  std::ofstream(dir.path / "tet.obj")
      << "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n";
  const std::string path = dir.write(
      "good.lua",
      "local h = require('helper')\n"
      "return {\n"
      "  name = 'good',\n"
      "  root = 'b',\n"
      "  links = {\n"
      "    { name = 'a', mass = 1, color = {1, 0, 0},\n"
      "      shapes = { { cylinder = {0.02, h.size}, axis = 'x', mass = 0.25 },\n"
      "                 { mesh = 'tet.obj', scale = 0.1, at = {0, 0, 1} } } },\n"
      "    { name = 'b', mass = 2, shapes = { { box = {h.size, 0.1, 0.1}, rot = {0, 0, 0.5} } } },\n"
      "  },\n"
      "  joints = { { name = 'spin', parent = 'b', child = 'a', pivot = {0, 0, 0},\n"
      "               axis = {0, 0, 2}, continuous = true, torque = 0, speed = 1 } },\n"
      "  docks = {\n"
      "    { name = 'side', link = 'a', at = {0, 0.02, 0}, normal = {0, 3, 0} },\n"
      "    { name = 'top', link = 'b', at = {0, 0, 0.05}, normal = {0, 0, 1}, gender = 'male',\n"
      "      size = 0.02, symmetry = 2 },\n"
      "  },\n"
      "}\n");
  const rm3d::ModuleTypeDef t = rm3d::loadModuleType(path, kRoot);
  CHECK(t.rootLink == 1);
  const rm3d::ShapeDef& cyl = t.links[0].shapes[0];
  CHECK(cyl.kind == rm3d::ShapeKind::Cylinder);
  CHECK(cyl.length == doctest::Approx(0.1));
  CHECK((cyl.pose.rot * Vec3::UnitZ()).isApprox(Vec3::UnitX()));
  CHECK(cyl.mass == 0.25);
  const rm3d::ShapeDef& hull = t.links[0].shapes[1];
  CHECK(hull.kind == rm3d::ShapeKind::Hull);
  CHECK(hull.points.size() == 4);
  CHECK(std::any_of(hull.points.begin(), hull.points.end(),
                    [](const Vec3& p) { return (p - Vec3(0.1, 0, 0)).norm() < 1e-7; }));  // scaled
  CHECK(hull.pose.pos.isApprox(Vec3(0, 0, 1)));
  CHECK(hull.mass < 0);  // by volume
  CHECK(t.links[0].color[0] == 1.0f);
  CHECK(t.links[0].color[3] == 1.0f);
  CHECK((t.links[1].shapes[0].pose.rot * Vec3::UnitX()).isApprox(Vec3(std::cos(0.5), std::sin(0.5), 0)));
  CHECK_FALSE(t.joints[0].limited);
  CHECK(t.joints[0].axis.isApprox(Vec3::UnitZ()));
  CHECK(t.joints[0].maxTorque == 0);
  CHECK(t.docks[0].normal.isApprox(Vec3::UnitY()));
  CHECK(t.docks[0].up.isApprox(Vec3::UnitZ()));  // default: z projected
  CHECK(t.docks[1].up.isApprox(Vec3::UnitX()));  // default when the normal is along z
  CHECK(t.docks[1].gender == rm3d::Gender::Male);
  CHECK(t.docks[1].symmetry == 2);
  CHECK(t.docks[0].gender == rm3d::Gender::None);
  CHECK(t.docks[0].size == 0.034);
}

TEST_CASE("bad module-type files throw InputError naming the file and the place") {
  TempDir dir;

  SUBCASE("the baseline file is fine") {
    CHECK(loadError(dir.write("ok.lua", twoLinks())) == "");
  }
  SUBCASE("unknown key") {
    const std::string msg = loadError(dir.write("bad_key.lua", twoLinks("box = {0.1, 0.1, 0.1}, sise = 2")));
    CHECK_MESSAGE(contains(msg, "bad_key.lua: links[1].shapes[1]: unknown key 'sise'"), msg);
    CHECK_MESSAGE(contains(msg, "expected one of: box, sphere"), msg);
  }
  SUBCASE("unknown link name in a joint") {
    std::string text = twoLinks();
    text.replace(text.find("child = 'b'"), 11, "child = 'nolink'");
    const std::string msg = loadError(dir.write("bad_link.lua", text));
    CHECK_MESSAGE(contains(msg, "bad_link.lua: joints[1].child: unknown link 'nolink'"), msg);
  }
  SUBCASE("unknown link name in a dock") {
    std::string text = twoLinks();
    text.replace(text.find("link = 'a'"), 10, "link = 'zz'");
    const std::string msg = loadError(dir.write("bad_dock.lua", text));
    CHECK_MESSAGE(contains(msg, "bad_dock.lua: docks[1].link: unknown link 'zz'"), msg);
  }
  SUBCASE("missing file") {
    const std::string msg = loadError((dir.path / "missing.lua").string());
    CHECK_MESSAGE(contains(msg, "missing.lua"), msg);
  }
  SUBCASE("bad mesh path") {
    const std::string msg = loadError(dir.write("bad_mesh.lua", twoLinks("mesh = 'meshes/nowhere.obj'")));
    CHECK_MESSAGE(contains(msg, "bad_mesh.lua: links[1].shapes[1].mesh:"), msg);
    CHECK_MESSAGE(contains(msg, "meshes/nowhere.obj"), msg);
  }
  SUBCASE("unreadable mesh") {
    dir.write("empty.obj", "# nothing here\n");
    const std::string msg = loadError(dir.write("bad_mesh2.lua", twoLinks("mesh = 'empty.obj'")));
    CHECK_MESSAGE(contains(msg, "bad_mesh2.lua: links[1].shapes[1].mesh:"), msg);
    CHECK_MESSAGE(contains(msg, "empty.obj"), msg);
  }
  SUBCASE("Lua syntax error carries file and line") {
    const std::string msg =
        loadError(dir.write("syntax.lua", "return {\n  name = 'x',\n  links = { { name = } },\n}\n"));
    CHECK_MESSAGE(contains(msg, "syntax.lua:3:"), msg);
  }
  SUBCASE("Lua runtime error carries file and line") {
    const std::string msg = loadError(dir.write("runtime.lua", "local t = nil\nreturn t.x\n"));
    CHECK_MESSAGE(contains(msg, "runtime.lua:2:"), msg);
  }
  SUBCASE("endless loop hits the instruction budget") {
    const std::string msg = loadError(dir.write("loop.lua", "while true do end\n"));
    CHECK_MESSAGE(contains(msg, "loop.lua:1:"), msg);
    CHECK_MESSAGE(contains(msg, "instruction budget"), msg);
  }
  SUBCASE("not a table") {
    const std::string msg = loadError(dir.write("nothing.lua", "return 42\n"));
    CHECK_MESSAGE(contains(msg, "nothing.lua: expected the file to return a table"), msg);
  }
  SUBCASE("missing required field") {
    std::string text = twoLinks();
    text.replace(text.find("mass = 1, "), 10, "");
    const std::string msg = loadError(dir.write("no_mass.lua", text));
    CHECK_MESSAGE(contains(msg, "no_mass.lua: links[1]: missing required field 'mass'"), msg);
  }
  SUBCASE("wrong type") {
    std::string text = twoLinks();
    text.replace(text.find("mass = 1"), 8, "mass = 'heavy'");
    const std::string msg = loadError(dir.write("type.lua", text));
    CHECK_MESSAGE(contains(msg, "type.lua: links[1].mass: expected a number, got the string 'heavy'"), msg);
  }
  SUBCASE("negative mass") {
    std::string text = twoLinks();
    text.replace(text.find("mass = 1"), 8, "mass = -1");
    const std::string msg = loadError(dir.write("neg.lua", text));
    CHECK_MESSAGE(contains(msg, "neg.lua: links[1].mass:"), msg);
  }
  SUBCASE("negative shape mass") {
    const std::string msg = loadError(dir.write("neg_shape.lua", twoLinks("sphere = 0.1, mass = -0.5")));
    CHECK_MESSAGE(contains(msg, "neg_shape.lua: links[1].shapes[1].mass: must not be negative"), msg);
  }
  SUBCASE("negative torque") {
    std::string text = twoLinks();
    text.replace(text.find("torque = 1"), 10, "torque = -2");
    const std::string msg = loadError(dir.write("torque.lua", text));
    CHECK_MESSAGE(contains(msg, "torque.lua: joints[1].torque: must not be negative"), msg);
  }
  SUBCASE("lower above upper") {
    std::string text = twoLinks();
    text.replace(text.find("lower = -1"), 10, "lower = 2");
    const std::string msg = loadError(dir.write("limits.lua", text));
    CHECK_MESSAGE(contains(msg, "limits.lua: joints[1]: lower (2) is greater than upper (1)"), msg);
  }
  SUBCASE("zero axis") {
    std::string text = twoLinks();
    text.replace(text.find("axis = {0, 0, 1}"), 16, "axis = {0, 0, 0}");
    const std::string msg = loadError(dir.write("axis.lua", text));
    CHECK_MESSAGE(contains(msg, "axis.lua: joints[1].axis: direction must not be zero"), msg);
  }
  SUBCASE("vector with the wrong count") {
    std::string text = twoLinks();
    text.replace(text.find("pivot = {0.1, 0, 0}"), 19, "pivot = {0.1, 0}");
    const std::string msg = loadError(dir.write("pivot.lua", text));
    CHECK_MESSAGE(contains(msg, "pivot.lua: joints[1].pivot: expected {x, y, z}"), msg);
  }
  SUBCASE("duplicate names") {
    std::string text = twoLinks();
    text.replace(text.find("name = 'b'"), 10, "name = 'a'");
    const std::string msg = loadError(dir.write("dup.lua", text));
    CHECK_MESSAGE(contains(msg, "dup.lua: links[2].name: duplicate link name 'a' (also links[1])"), msg);
  }
  SUBCASE("two shape kinds") {
    const std::string msg = loadError(dir.write("kinds.lua", twoLinks("box = {1, 1, 1}, sphere = 1")));
    CHECK_MESSAGE(contains(msg, "kinds.lua: links[1].shapes[1]: expected exactly one of box, sphere"), msg);
  }
  SUBCASE("bad gender") {
    const std::string msg =
        loadError(dir.write("gender.lua", twoLinks("sphere = 0.1", "", ", gender = 'both'")));
    CHECK_MESSAGE(contains(msg, "gender.lua: docks[1].gender: unknown gender 'both'"), msg);
  }
  SUBCASE("up not perpendicular to the normal") {
    const std::string msg = loadError(dir.write("up.lua", twoLinks("sphere = 0.1", "", ", up = {1, 0, 1}")));
    CHECK_MESSAGE(contains(msg, "up.lua: docks[1].up: up must be perpendicular to normal"), msg);
  }
  SUBCASE("limits on a continuous joint") {
    const std::string msg = loadError(dir.write("cont.lua", twoLinks("sphere = 0.1", ", continuous = true")));
    CHECK_MESSAGE(contains(msg, "cont.lua: joints[1]: a continuous joint has no lower/upper limits"), msg);
  }
  SUBCASE("link not joined to the root") {
    std::string text = twoLinks();
    text.replace(text.find("  joints = {"), text.find("  docks") - text.find("  joints = {"), "");
    const std::string msg = loadError(dir.write("loose.lua", text));
    CHECK_MESSAGE(contains(msg, "loose.lua: links[2]: link 'b' is not connected"), msg);
  }
  SUBCASE("a table that contains itself") {
    const std::string msg =
        loadError(dir.write("cycle.lua", "local t = { name = 'x' }\nt.links = { t }\nreturn t\n"));
    CHECK_MESSAGE(contains(msg, "cycle.lua: links[1]: a table that contains itself"), msg);
  }
  SUBCASE("file names are shown relative to the project root") {
    const std::string root = (dir.path / "proj").string();
    const std::string msg = loadError(
        dir.write("proj/assets/modules/rel.lua", twoLinks("box = {0.1, 0.1, 0.1}, sise = 2")), root);
    CHECK_MESSAGE(msg.rfind("assets/modules/rel.lua: links[1].shapes[1]: unknown key 'sise'", 0) == 0, msg);
  }
}

TEST_CASE("SuperBot brackets collide as one hull each, with the mass properties of their plates") {
  const rm3d::ModuleTypeDef t = rm3d::loadModuleType(kRoot + "/assets/modules/superbot.lua", kRoot);
  for (const char* name : {"front_outer", "back_outer"}) {
    CAPTURE(name);
    const rm3d::LinkDef& l = t.links[size_t(t.findLink(name))];
    CHECK(l.shapes.size() == 3);  // drawn: end plate and two side plates
    REQUIRE(l.collision.size() == 1);
    CHECK(l.collision[0].kind == rm3d::ShapeKind::Hull);
    CHECK(&l.collisionShapes() == &l.collision);
    CHECK(l.collision[0].points.size() < l.shapes[0].points.size() + l.shapes[1].points.size());
    // Physics builds the part from the collision shapes: same mass, centre of mass and inertia.
    const rm3d::MassProps visual = rm3d::compoundMassProps(l.shapes, l.mass);
    const rm3d::MassProps collision = rm3d::compoundMassProps(l.collision, l.mass);
    CHECK((visual.com - collision.com).norm() < 1e-12);
    CHECK((visual.inertia - collision.inertia).norm() < 1e-12 * visual.inertia.norm());
    CHECK(visual.inertia.norm() > 1e-6);
  }
  for (const char* name : {"front_inner", "back_inner"}) {
    const rm3d::LinkDef& l = t.links[size_t(t.findLink(name))];
    CHECK(l.collision.empty());
    CHECK(&l.collisionShapes() == &l.shapes);
  }
  // The bracket hull holds every point of the plates (or contacts would be lost).
  const rm3d::LinkDef& fo = t.links[size_t(t.findLink("front_outer"))];
  Vec3 lo = Vec3::Constant(1e9), hi = Vec3::Constant(-1e9), clo = lo, chi = hi;
  for (const rm3d::ShapeDef& s : fo.shapes)
    for (const Vec3& p : s.points) {
      lo = lo.cwiseMin(s.pose * p);
      hi = hi.cwiseMax(s.pose * p);
    }
  for (const Vec3& p : fo.collision[0].points) {
    clo = clo.cwiseMin(fo.collision[0].pose * p);
    chi = chi.cwiseMax(fo.collision[0].pose * p);
  }
  CHECK((lo - clo).norm() < 1e-6);  // the OBJ files keep 6 decimals
  CHECK((hi - chi).norm() < 1e-6);
}

TEST_CASE("bad collision lists name the file and the place") {
  TempDir dir;
  auto withCollision = [&](const std::string& file, const std::string& collision) {
    return loadError(dir.write(file,
                               "return { name = 't', links = { { name = 'a', mass = 1, shapes = { { box = "
                               "{0.1, 0.1, 0.1} } }, collision = " +
                                   collision + " } } }"));
  };
  std::string msg = withCollision("c1.lua", "{ box = {0.1, 0.1, 0.1} }");
  CHECK_MESSAGE(contains(msg, "c1.lua: links[1].collision: expected a list of shapes"), msg);
  msg = withCollision("c2.lua", "{}");
  CHECK_MESSAGE(contains(msg, "c2.lua: links[1].collision: expected at least one shape"), msg);
  msg = withCollision("c3.lua", "{ { sphere = 0.1, mass = 1 } }");
  CHECK_MESSAGE(contains(msg, "c3.lua: links[1].collision[1].mass: collision shapes carry no mass"), msg);
  msg = withCollision("c4.lua", "{ { sphere = 0.1 }, { sphere = -1 } }");
  CHECK_MESSAGE(contains(msg, "c4.lua: links[1].collision[2].sphere: must be greater than 0"), msg);
  CHECK(withCollision("ok.lua", "{ { sphere = 0.1 } }") == "");
}
