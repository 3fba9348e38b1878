-- ATRON: a lattice-type module, a sphere 0.11 m across made of two hemispheres (`north`,
-- `south`, 0.425 kg each) that turn against each other about the polar axis z through the
-- joint `equator` (continuous, 1.5 N m, 1 rad/s), with eight gendered docks (see docs/module-types.md).
-- The format of this file is documented at the top of assets/modules/superbot.lua.
--
-- ===== Geometry =====
--
-- Module frame: origin at the centre of the sphere, z the polar axis (towards the north pole).
-- Both hemispheres are the convex mesh assets/meshes/atron_hemisphere.obj (radius 0.055, made by
-- assets/meshes/make_atron_meshes.lua): `north` as is, `south` turned 180 degrees about x. The
-- hemispheres' flat faces meet at z = 0; `south` (the child) turns about +z relative to `north`
-- (the parent, and the root: the module's pose is the north hemisphere's). They collide as
-- assets/meshes/atron_hemisphere_collision.obj, the same dome in 77 points instead of 193.
--
-- ===== Docks =====
--
-- Dock d_i (d = n or s, i = 0..3) sits on the sphere at azimuth i * 90 degrees (from +x towards
-- +y) and elevation +45 (n) or -45 (s) degrees:  at = 0.055 * (cos45 cos(az), cos45 sin(az),
-- +-sin45), with the outward radial normal. So n0 points along (1, 0, 1)/sqrt2, n1 along
-- (0, 1, 1)/sqrt2, s0 along (1, 0, -1)/sqrt2, s3 along (0, -1, -1)/sqrt2, and so on.
--
--   genders   n0 male, n1 female, n2 male, n3 female;  s0 male, s1 female, s2 male, s3 female.
--             The docks leaning towards the module's x axis (i = 0, 2) are male, those leaning
--             towards y (i = 1, 3) female, in both hemispheres. (Turning the north hemisphere
--             180 degrees about x gives the south one, docks included: n0 -> s0, n1 -> s3,
--             n2 -> s2, n3 -> s1, with the same genders.)
--   up        the tangent from the dock towards its own hemisphere's pole ("poleward"):
--             (-cos(az), -sin(az), +1)/sqrt2 for n, (-cos(az), -sin(az), -1)/sqrt2 for s.
--   symmetry  1: a dock mates in one way only (orientation 0).
--
-- Why this works. world.connect(a, da, b, db, 0) gives b's dock the normal opposite to a's and
-- the same `up`. Write a's dock normal as (P + t)/sqrt2 and its up as (P - t)/sqrt2, with P a's
-- pole on that side and t the unit azimuth direction. b's dock must then be (-P - t)/sqrt2 with
-- up (P - t)/sqrt2, so b's pole on that side is -t and its dock's azimuth direction is -P: b's
-- centre lands 0.11 m from a's along a's dock normal, and b's polar axis lies along t, orthogonal
-- to a's. That is exactly the ATRON lattice (the "surface-centred cubic" lattice: centres 0.11 m
-- apart along (+-1, 0, +-1)/sqrt2-type directions, neighbours' axes orthogonal).
--
-- Genders in the lattice. Give the lattice axes x, y, z a cyclic order (x -> y -> z -> x) and
-- place every module so that its own x axis lies along the lattice axis that follows its polar
-- axis: polar axis along z -> own x along +-x, polar along x -> own x along +-y, polar along y ->
-- own x along +-z (which way each axis points, and which pole is up, are free). A dock's gender
-- depends only on which lattice axis it leans towards (male towards the module's own x line,
-- female towards its y line). For neighbours a (polar axis k) and b (polar axis j), a's facing
-- dock leans towards j and b's towards k; by the rule a's x line is j exactly when b's x line is
-- not k, so one dock is male and the other female: every facing pair in the lattice is
-- male-female. Conversely every connect that the genders allow (orientation 0) puts b in the
-- lattice obeying the same rule, so lattices grown with world.connect are consistent everywhere,
-- not only at the docks that were connected (tests/worlds/atron_lattice.lua checks both).
-- Note: turning one hemisphere by an odd multiple of 90 degrees swaps two lattice axes for
-- everything it carries, which reverses the cyclic order for that part: docks that then come to
-- face the rest of the lattice are male-male or female-female until a second quarter turn.

local kMesh = "assets/meshes/atron_hemisphere.obj"  -- from the project root, so variants
local kCollision = "assets/meshes/atron_hemisphere_collision.obj"  -- elsewhere can require this file
local kRadius = 0.055
local c = math.sqrt(0.5)

local function dock(hemisphere, i)
  local az = i * math.pi / 2
  -- Exact values at multiples of 90 degrees (no 6e-17 instead of 0).
  local ca = ({ 1, 0, -1, 0 })[i + 1]
  local sa = ({ 0, 1, 0, -1 })[i + 1]
  assert(math.abs(ca - math.cos(az)) < 1e-12 and math.abs(sa - math.sin(az)) < 1e-12)
  local h = hemisphere == "n" and 1 or -1
  return {
    name = hemisphere .. i,
    link = hemisphere == "n" and "north" or "south",
    at = { kRadius * c * ca, kRadius * c * sa, kRadius * c * h },
    normal = { c * ca, c * sa, c * h },
    up = { -c * ca, -c * sa, c * h },
    gender = (i % 2 == 0) and "male" or "female",
    size = 0.03,
    symmetry = 1,
  }
end

local docks = {}
for _, hemisphere in ipairs({ "n", "s" }) do
  for i = 0, 3 do docks[#docks + 1] = dock(hemisphere, i) end
end

return {
  name = "atron",
  root = "north",
  links = {
    { name = "north", mass = 0.425, color = { 0.2, 0.42, 0.85 }, friction = 1.0, rolling_friction = 0.002,
      shapes = { { mesh = kMesh } }, collision = { { mesh = kCollision } } },
    { name = "south", mass = 0.425, color = { 0.92, 0.92, 0.88 }, friction = 1.0, rolling_friction = 0.002,
      shapes = { { mesh = kMesh, quat = { 0, 1, 0, 0 } } },  -- 180 degrees about x
      collision = { { mesh = kCollision, quat = { 0, 1, 0, 0 } } } },
  },
  joints = {
    { name = "equator", parent = "north", child = "south", pivot = { 0, 0, 0 }, axis = { 0, 0, 1 },
      continuous = true, torque = 1.5, speed = 1, gain = 20 },
  },
  docks = docks,
  sensors = {
    { type = "accelerometer", link = "north" },
    { type = "gyro", link = "north" },
    { type = "orientation" },
    { type = "position" },
    { type = "contact", link = "north" },
    { type = "contact", link = "south" },
  },
}
