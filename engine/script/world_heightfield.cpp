// World side: world.heightfield{...}, terrain from a grayscale image, and its handle
// (rm3d.Heightfield): the surface height anywhere, the grid's size, its bounds.
#include <cmath>
#include <memory>
#include <string>

#include "assets/height_image.h"
#include "core/error.h"
#include "script/lua_options.h"
#include "script/lua_vm.h"
#include "script/world_bindings.h"
#include "world/world.h"

namespace rm3d {

namespace {

constexpr const char* kHeightfieldMeta = "rm3d.Heightfield";

const World& world(lua_State* L) {
  return scriptWorld(L);
}
WorldEditor& editor(lua_State* L) {
  return scriptEditor(L);
}

/// The obstacle a Heightfield handle stands for.
const World::Obstacle& checkHeightfield(lua_State* L) {
  const int index = *static_cast<int*>(luaL_checkudata(L, 1, kHeightfieldMeta));
  return world(L).obstacles()[size_t(index)];
}

/// t.size as {sx, sy}: two positive numbers (metres) no larger than `bounds`.
void sizeField(lua_State* L, const char* fn, double bounds, double& sx, double& sy) {
  const int t = lua_getfield(L, 1, "size");
  if (t == LUA_TNIL) luaL_error(L, "%s: option 'size' ({sx, sy}, metres along x and y) is required", fn);
  double v[2] = {0, 0};
  bool ok = t == LUA_TTABLE && lua_rawlen(L, -1) == 2;
  for (int i = 0; ok && i < 2; ++i) {
    int isnum = 0;
    lua_rawgeti(L, -1, i + 1);
    v[i] = lua_tonumberx(L, -1, &isnum);
    lua_pop(L, 1);
    ok = isnum && v[i] > 0 && v[i] <= bounds;
  }
  if (!ok)
    luaL_error(
        L,
        "%s: option 'size' must be {sx, sy}: two positive numbers (metres) at most the world bounds (%s m)",
        fn, numText(bounds).s);
  lua_pop(L, 1);
  sx = v[0];
  sy = v[1];
}

/// The grid of an image: pixel (column i, row r from the top) is the sample at x = -sx/2 + i
/// cells, y = +sy/2 - r cells (the picture seen from above, x to the right, y up).
std::shared_ptr<HeightGrid> gridFromImage(const GrayImage& img, double sx, double sy, double height) {
  auto g = std::make_shared<HeightGrid>();
  g->nx = img.width;
  g->ny = img.height;
  g->sx = sx;
  g->sy = sy;
  g->maxHeight = height;
  g->heights.resize(img.values.size());
  for (int j = 0; j < g->ny; ++j)
    for (int i = 0; i < g->nx; ++i)
      g->heights[size_t(j) * size_t(g->nx) + size_t(i)] =
          float(height * img.values[size_t(g->ny - 1 - j) * size_t(g->nx) + size_t(i)]);
  return g;
}

/// hf:height_at(x, y) -> z of the surface over the world point (x, y), or nil off the terrain
int hfHeightAt(lua_State* L) {
  const World::Obstacle& o = checkHeightfield(L);
  const double x = luaL_checknumber(L, 2), y = luaL_checknumber(L, 3);
  const Pose p = world(L).obstaclePose(o.part);
  const HeightGrid& g = *o.shape.grid;
  const double lx = x - p.pos.x(), ly = y - p.pos.y();
  const double slack = 1e-9 * (g.sx + g.sy);
  if (!(std::abs(lx) <= g.sx / 2 + slack && std::abs(ly) <= g.sy / 2 + slack)) {
    lua_pushnil(L);
    return 1;
  }
  lua_pushnumber(L, p.pos.z() + g.heightAt(lx, ly));
  return 1;
}

/// hf:position() -> {x, y, z}: the centre of the terrain in x and y, its base (black) in z
int hfPosition(lua_State* L) {
  pushVec3(L, world(L).obstaclePose(checkHeightfield(L).part).pos);
  return 1;
}

/// hf:orientation() -> {w, x, y, z}: always upright (terrain is axis-aligned)
int hfOrientation(lua_State* L) {
  pushQuat(L, world(L).obstaclePose(checkHeightfield(L).part).rot);
  return 1;
}

/// hf:velocity() -> {0, 0, 0}: terrain is static
int hfVelocity(lua_State* L) {
  checkHeightfield(L);
  pushVec3(L, Vec3::Zero());
  return 1;
}

/// hf:count() -> the number of height samples (image pixels)
int hfCount(lua_State* L) {
  const HeightGrid& g = *checkHeightfield(L).shape.grid;
  lua_pushinteger(L, lua_Integer(g.nx) * g.ny);
  return 1;
}

/// hf:resolution() -> nx, ny: samples along x and y (the image's width and height in pixels)
int hfResolution(lua_State* L) {
  const HeightGrid& g = *checkHeightfield(L).shape.grid;
  lua_pushinteger(L, g.nx);
  lua_pushinteger(L, g.ny);
  return 2;
}

/// hf:bounds() -> {min = {x, y, z}, max = {x, y, z}}: the box the terrain can fill
int hfBounds(lua_State* L) {
  const World::Obstacle& o = checkHeightfield(L);
  const HeightGrid& g = *o.shape.grid;
  const Vec3 c = world(L).obstaclePose(o.part).pos;
  lua_createtable(L, 0, 2);
  pushVec3(L, c - Vec3(g.sx / 2, g.sy / 2, 0));
  lua_setfield(L, -2, "min");
  pushVec3(L, c + Vec3(g.sx / 2, g.sy / 2, g.maxHeight));
  lua_setfield(L, -2, "max");
  return 1;
}

}  // namespace

/// world.heightfield{image=, size={sx, sy}, height=, at={x, y, z}, friction=} -> Heightfield:
/// static terrain from a grayscale image, black at at.z and white at at.z + height, centred on
/// (at.x, at.y), one height sample per pixel
int worldHeightfield(lua_State* L) {
  const char* fn = "world.heightfield";
  checkOptionKeys(L, 1, fn, {"image", "size", "height", "at", "friction"});
  const char* image = optStringField(L, 1, fn, "image");
  if (!image) return luaL_error(L, "%s: option 'image' (a grayscale image file, e.g. a PNG) is required", fn);
  const double bounds = world(L).settings().limits.bounds;
  double sx = 0, sy = 0;
  sizeField(L, fn, bounds, sx, sy);
  lua_getfield(L, 1, "height");
  const bool haveHeight = !lua_isnil(L, -1);
  lua_pop(L, 1);
  if (!haveHeight) return luaL_error(L, "%s: option 'height' (metres from black to white) is required", fn);
  const double height = optNumberField(L, 1, fn, "height", 0);
  if (!(height >= 0 && height <= bounds))
    return luaL_error(L, "%s: height must be 0 or more metres, at most the world bounds (%s m), got %s", fn,
                      numText(bounds).s, numText(height).s);
  const Vec3 at = optVec3Field(L, 1, fn, "at", Vec3::Zero());
  checkInBounds(L, fn, at);
  const double friction = optNumberField(L, 1, fn, "friction", 0.8);
  if (friction < 0)
    return luaL_error(L, "%s: friction must not be negative, got %s", fn, numText(friction).s);
  int index = -1;
  callWorld(L, fn, [&] {  // raises the Lua error after every C++ object is gone
    WorldEditor& e = editor(L);
    const World& w = e.view();
    const std::string path = w.resolvePath(image);
    if (path.empty()) throw InputError(std::string("image '") + image + "' not found " + w.resolveLookedIn());
    GrayImage img;
    std::string err;
    if (!loadGrayImage(path, img, err)) throw InputError("image " + err);
    if (img.width < 2 || img.height < 2)
      throw InputError("image '" + path + "' is " + std::to_string(img.width) + " x " +
                       std::to_string(img.height) + " pixels; a heightfield needs at least 2 x 2");
    ShapeDef s;
    s.kind = ShapeKind::Heightfield;
    s.grid = gridFromImage(img, sx, sy, height);
    s.source = image;
    Pose pose;
    pose.pos = at;
    e.addObstacle(s, pose, 0, friction);
    index = int(w.obstacles().size()) - 1;
    return 0;
  });
  *static_cast<int*>(lua_newuserdatauv(L, sizeof(int), 0)) = index;
  luaL_setmetatable(L, kHeightfieldMeta);
  return 1;
}

void openHeightfieldHandle(lua_State* L) {
  static const luaL_Reg methods[] = {
      {"height_at", hfHeightAt}, {"position", hfPosition}, {"orientation", hfOrientation},
      {"velocity", hfVelocity},  {"count", hfCount},       {"resolution", hfResolution},
      {"bounds", hfBounds},      {nullptr, nullptr}};
  luaL_newmetatable(L, kHeightfieldMeta);
  sealMetatable(L);
  luaL_newlib(L, methods);
  lua_setfield(L, -2, "__index");
  lua_pop(L, 1);
}

}  // namespace rm3d
