-- SuperBot: a chain-type module with three joints (pitch, roll, yaw) and six genderless docks,
-- about 0.19 m long dock face to dock face, 0.084 m square, 0.72 kg (see docs/module-types.md).
--
-- ===== Module-type file format (the reference for every file in assets/modules/) =====
--
-- A module-type file is a Lua chunk (sandboxed: no io/os; `require` finds files in this folder,
-- then in <project>/lua) that returns one table. All units SI: metres, kilograms, radians,
-- seconds, newton-metres. Every pose is given in the MODULE FRAME AT ZERO JOINT ANGLES, which is
-- also every link's own frame, so a joint's pivot and axis mean the same in both of its links.
-- Unknown keys, wrong types and bad values are errors that name this file and the place, e.g.
-- "assets/modules/superbot.lua: links[2].shapes[1]: unknown key 'sise' (...)".
--
--   return {
--     name   = "superbot",            -- required, the type name
--     root   = "front_inner",         -- optional (default: the first link): its frame is the
--                                     -- module frame
--     links  = { link, ... },         -- required, at least one
--     joints = { joint, ... },        -- optional; every link must be joined to the root
--     docks  = { dock, ... },         -- optional
--     sensors = { sensor, ... },      -- optional (joint:<name>, dock:<name> need no entry)
--   }
--
--   link  = { name = "...",             -- required, unique among links
--             mass = 0.13,              -- required, kg, > 0
--             color = {r, g, b[, a]},   -- optional, 0..1 (default light grey)
--             friction = 1.0,           -- optional, >= 0 (default 1)
--             rolling_friction = 0,     -- optional, m, 0 to 0.1: the lever arm of its
--                                       -- resistance to rolling and spinning (default 0)
--             shapes = { shape, ... },  -- required, at least one: what the link is made
--                                       -- of; drawn, and its mass properties come from them
--             collision = { shape, ... } } -- optional separate collision geometry (like
--                                       -- URDF's <collision> beside <visual>): physics
--                                       -- collides with these instead of `shapes`, while
--                                       -- mass, centre of mass and inertia stay those of
--                                       -- `shapes`; same shape format, without `mass`
--
--   shape = exactly one of
--             box = {x, y, z}                 -- full side lengths
--             sphere = r
--             cylinder = {radius, length}     -- along the shape's z axis; the convenience
--                                             -- axis = "x" | "y" | "z" turns it onto that axis
--             mesh = "file.obj", scale = 1    -- a convex hull of the file's points (anything
--                                             -- assimp reads: OBJ, STL, ...), found relative to
--                                             -- this file's folder, then the project root
--           plus optional
--             at = {x, y, z}                  -- position of the shape's origin (default 0)
--             rot = {roll, pitch, yaw}        -- radians, about fixed x, then y, then z
--             quat = {w, x, y, z}             -- or a quaternion (normalised when read)
--             mass = 0.05                     -- kg taken by this shape; shapes without one share
--                                             -- the rest of the link's mass by volume
--
--   joint = { name = "...",             -- required, unique among joints
--             parent = "link", child = "link",  -- required; the angle turns child about axis
--             pivot = {x, y, z},        -- required, a point on the axis
--             axis = {x, y, z},         -- required, normalised when read, not zero
--             lower = -1.57, upper = 1.57,      -- required limits (rad), lower <= upper ...
--             continuous = true,        -- ... unless the joint turns without limits
--             torque = 2.5,             -- required, motor torque limit, N m, >= 0
--             speed = 3,                -- required, motor speed limit, rad/s, >= 0
--             gain = 20,                -- optional servo gain, 1/s (default 20)
--             stiffness = 300 }         -- optional, N m/rad: a holding servo yields torque /
--                                       -- stiffness under load (default 0: rigid; exact solver)
--
--   dock  = { name = "...",             -- required, unique among docks
--             link = "link",            -- required, the link carrying the face
--             at = {x, y, z},           -- required, centre of the face
--             normal = {x, y, z},       -- required, outward, normalised when read
--             up = {x, y, z},           -- optional reference direction in the face (must be
--                                       -- perpendicular to normal); default: +z projected
--                                       -- into the face, or +x when the normal is near z
--             gender = "none",          -- optional: "none" (mates any "none"), "male" or
--                                       -- "female" (mate each other) (default "none")
--             size = 0.034,             -- optional, side of the square face, m (default 0.034)
--             symmetry = 4,             -- optional, how many ways the face mates about its
--                                       -- normal (default 4: square)
--             -- run-time docking (all optional): a free, enabled dock captures a compatible
--             -- one whose face is within capture_radius and looks back within capture_angle,
--             -- draws it in, and latches once within latch_distance and latch_angle
--             capture_radius = 0.03,    -- m
--             capture_angle = 0.5236,   -- rad (30 deg)
--             latch_distance = 0.004,   -- m (at most capture_radius)
--             latch_angle = 0.0873,     -- rad (5 deg), for the normals and the orientation
--             capture = "joint",        -- "joint": a capture joint draws the faces together
--                                       -- (needs the exact solver); "magnet": forces `pull`
--             capture_speed = 0.05,     -- m/s: the joint closes the faces at most this fast
--             capture_turn_speed = 1,   -- rad/s: ... and turns them at most this fast
--             capture_force = 20,       -- N: the most force the joint exerts
--             capture_torque = 1,       -- N m: the most torque the joint exerts
--             capture_time = 3,         -- s: a capture not latched by then is reported stalled
--             pull = 2,                 -- N, the magnet's pull (0: no attraction)
--             strength = 100,           -- N: the connection breaks above this force ...
--             strength_torque = 10 }    -- N m: ... or above this torque through it
--
--   sensor = { type = "accelerometer" | "gyro" | "orientation" | "position" | "contact" | "range",
--              link = "link",           -- where it sits (default: the root; required for contact)
--              -- range only:
--              name = "front",          -- read as "range:front"
--              at = {x, y, z}, dir = {x, y, z},  -- ray origin and direction in the link frame
--              min = 0.02, max = 2.0 }  -- metres; nearer or farther reads nil
--   Names read by behaviours: accelerometer (m/s^2, gravity included, link frame), gyro (rad/s,
--   link frame), orientation ({w,x,y,z}), position ({x,y,z}), contact:<link> (true when the
--   link touches anything), range:<name> (metres or nil).
--
-- ===== SuperBot =====
--
-- Module frame: x forward, y left, z up when the module lies flat. Two inner halves (boxes)
-- roll against each other about x; each carries an outer U-bracket (an end plate and two
-- D-shaped side plates, convex meshes made by assets/meshes/make_superbot_meshes.lua): the front
-- bracket pitches about y at x = +0.043, the back one yaws about z at x = -0.043. The back
-- bracket is the front one turned by R = Rx(90 deg) * Rz(180 deg), computed below. Each bracket
-- collides as one convex hull (the D profile across the bracket's full width, which contains the
-- end plate): against the ground or any convex body it touches where the three plates would,
-- except inside the U, where the module's own inner half sits. One 38-point hull instead of three
-- hulls of 100 points makes contacts about half as costly (README, Speed).
-- Dock `up` references: +z for front, back, left and right; -x (towards the back of the
-- module) for up and down.

local kEndPlate = "assets/meshes/superbot_end_plate.obj"  -- from the project root, so variants
local kSidePlate = "assets/meshes/superbot_side_plate.obj" -- elsewhere can require this file
local kBracketHull = "assets/meshes/superbot_bracket_hull.obj"
local kOuterColor = { 0.95, 0.55, 0.1 }  -- orange brackets
local kInnerColor = { 0.25, 0.25, 0.28 } -- dark grey halves
local kLimit = math.pi / 2

-- Quaternions {w, x, y, z} (lua/vec.lua): just enough to turn the front bracket into the back one.
local vec = require("vec")
local quatAxisAngle, quatMul = vec.qaxis, vec.qmul

local function quatRotate(q, v)
  local p = quatMul(quatMul(q, { 0, v[1], v[2], v[3] }), { q[1], -q[2], -q[3], -q[4] })
  -- Snap rounding noise (1e-18 instead of 0) so the printed poses stay readable.
  local out = {}
  for i = 1, 3 do out[i] = math.abs(p[i + 1]) < 1e-12 and 0 or p[i + 1] end
  return out
end

-- Copies of shapes turned by q about the module origin (shapes must use `quat`, not `rot`).
local function turned(shapes, q)
  local out = {}
  for i, s in ipairs(shapes) do
    assert(s.rot == nil, "turned(): give the shape's rotation as quat")
    local t = {}
    for k, v in pairs(s) do t[k] = v end
    t.at = quatRotate(q, s.at or { 0, 0, 0 })
    t.quat = quatMul(q, s.quat or { 1, 0, 0, 0 })
    out[i] = t
  end
  return out
end

-- Front bracket: end plate outer face at x = 0.095; side plates pivot at x = 0.043 with their
-- outer faces at y = +-0.042, flush with the end plate, so the module is 0.084 m square.
local frontBracket = {
  { mesh = kEndPlate, at = { 0.089, 0, 0 } },
  { mesh = kSidePlate, at = { 0.043, 0.036, 0 } },
  { mesh = kSidePlate, at = { 0.043, -0.036, 0 } },
}
local frontBracketCollision = { { mesh = kBracketHull, at = { 0.043, 0, 0 } } }
local kBackTurn = quatMul(quatAxisAngle({ 1, 0, 0 }, math.pi / 2), quatAxisAngle({ 0, 0, 1 }, math.pi))

local function joint(name, parent, child, pivot, axis)
  return { name = name, parent = parent, child = child, pivot = pivot, axis = axis,
           lower = -kLimit, upper = kLimit, torque = 2.5, speed = 3, gain = 20,
           stiffness = 300 }
end

local function dock(name, link, at, normal, up)
  return { name = name, link = link, at = at, normal = normal, up = up,
           gender = "none", size = 0.034, symmetry = 4 }
end

return {
  name = "superbot",
  root = "front_inner",
  links = {
    { name = "front_outer", mass = 0.13, color = kOuterColor, friction = 1.0, shapes = frontBracket,
      collision = frontBracketCollision },
    { name = "front_inner", mass = 0.23, color = kInnerColor, friction = 1.0,
      shapes = { { box = { 0.053, 0.060, 0.060 }, at = { 0.0265, 0, 0 } } } },
    { name = "back_inner", mass = 0.23, color = kInnerColor, friction = 1.0,
      shapes = { { box = { 0.053, 0.060, 0.060 }, at = { -0.0265, 0, 0 } } } },
    { name = "back_outer", mass = 0.13, color = kOuterColor, friction = 1.0,
      shapes = turned(frontBracket, kBackTurn), collision = turned(frontBracketCollision, kBackTurn) },
  },
  joints = {
    joint("pitch", "front_inner", "front_outer", { 0.043, 0, 0 }, { 0, 1, 0 }),
    joint("roll", "front_inner", "back_inner", { 0, 0, 0 }, { 1, 0, 0 }),
    joint("yaw", "back_inner", "back_outer", { -0.043, 0, 0 }, { 0, 0, 1 }),
  },
  docks = {
    dock("front", "front_outer", { 0.095, 0, 0 }, { 1, 0, 0 }, { 0, 0, 1 }),
    dock("back", "back_outer", { -0.095, 0, 0 }, { -1, 0, 0 }, { 0, 0, 1 }),
    dock("left", "front_outer", { 0.058, 0.043, 0 }, { 0, 1, 0 }, { 0, 0, 1 }),
    dock("right", "front_outer", { 0.058, -0.043, 0 }, { 0, -1, 0 }, { 0, 0, 1 }),
    dock("up", "back_outer", { -0.058, 0, 0.043 }, { 0, 0, 1 }, { -1, 0, 0 }),
    dock("down", "back_outer", { -0.058, 0, -0.043 }, { 0, 0, -1 }, { -1, 0, 0 }),
  },
  -- joint:<name> and dock:<name> sensors exist for every joint and dock without being listed.
  sensors = {
    { type = "accelerometer", link = "front_inner" },
    { type = "gyro", link = "front_inner" },
    { type = "orientation" },
    { type = "position" },
    { type = "contact", link = "front_outer" },
    { type = "contact", link = "front_inner" },
    { type = "contact", link = "back_inner" },
    { type = "contact", link = "back_outer" },
  },
}
