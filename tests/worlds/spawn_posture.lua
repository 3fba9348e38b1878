-- world.spawn's `joints` sets a module's initial posture (by joint name or in joint order) and its
-- servos hold it; world.place_on_ground lowers a whole connected structure until its lowest point
-- touches the ground; lua/snake_chain.lua builds a chain already in its travelling wave's pose.
world.set{duration = 1.5}
world.ground{}

-- Posture: the links follow the joints, and the reported angles are the ones asked for.
local a = world.spawn("superbot", {at = {0, 1, 0.3}, fixed = true, joints = {pitch = 0.5, yaw = -0.3}})
local b = world.spawn("superbot", {at = {1, 1, 0.3}, fixed = true, joints = {0.2, 0.4, 0.6}})
local front0 = a:dock_position("front")

-- Placement: a module spawned high is lowered to rest on the ground (its frame 0.0430 m up).
local c = world.spawn("superbot", {at = {0, -1, 0.5}})
local moved = world.place_on_ground(c)
expect(math.abs(moved + (0.5 - 0.0430)) < 0.002, string.format("place_on_ground moved %.4f m", moved))
expect(math.abs(c:position().z - 0.0430) < 0.002, string.format("placed at z=%.4f", c:position().z))

-- A 12-module chain in its gait pose, held still (a wave of 4 modules: its humps are within the
-- servos' rating), put down on the ground as one piece.
local chain = require("snake_chain").build{n = 12, at = {0, -2}, amplitude = 0.4, lag = math.pi / 2,
                                           period = 1e6, behavior = "behaviors/snake.lua", name = "s"}
local low0 = math.huge
for _, m in ipairs(chain) do low0 = math.min(low0, m:position().z) end
expect(math.abs(low0 - 0.0430) < 0.01, string.format("the chain is put down on the ground (lowest frame %.4f m)", low0))

-- Errors name what was expected.
local function fails(text, f, ...)
  local ok, err = pcall(f, ...)
  expect(not ok and tostring(err):find(text, 1, true), text .. ": got " .. tostring(err))
end
fails("joints: joint 'pitch' angle 3.000000 is outside its limits", world.spawn, "superbot", {joints = {pitch = 3}})
fails("joints: superbot has no joint 'knee' (its joints: pitch, roll, yaw)", world.spawn, "superbot", {joints = {knee = 1}})
fails("joints: index 4 is out of range (superbot has 3 joints)", world.spawn, "superbot", {joints = {0, 0, 0, 0}})
fails("joints: joint 'roll' must be a finite angle in radians", world.spawn, "superbot", {joints = {roll = "x"}})
fails("option 'joints' must be a table of angles", world.spawn, "superbot", {joints = 1})
fails("world.place_on_ground: the height must be a finite number", world.place_on_ground, c, 0 / 0)

world.at(1.0, function()
  for name, want in pairs({pitch = 0.5, roll = 0, yaw = -0.3}) do
    expect(math.abs(a:joint_angle(name) - want) < 0.01, string.format("a %s %.4f, asked %.4f", name, a:joint_angle(name), want))
  end
  for name, want in pairs({pitch = 0.2, roll = 0.4, yaw = 0.6}) do
    expect(math.abs(b:joint_angle(name) - want) < 0.01, string.format("b %s %.4f, asked %.4f", name, b:joint_angle(name), want))
  end
  -- a's front dock is on the pitched bracket: turned 0.5 rad about y through the pivot at x = 0.043
  local f = a:dock_position("front")
  local r = 0.095 - 0.043
  local want = {x = 0.043 + r * math.cos(0.5), z = 0.3 - r * math.sin(0.5)}
  expect(math.abs(f.x - want.x) < 0.001 and math.abs(f.z - want.z) < 0.001,
         string.format("front dock at (%.4f, %.4f), expected (%.4f, %.4f)", f.x, f.z, want.x, want.z))
  expect(math.abs(front0.x - want.x) < 0.001, "the posture is there before the first step")
  expect(math.abs(c:position().z - 0.0430) < 0.002, string.format("placed module rests at z=%.4f", c:position().z))
  -- the chain holds its pose on the ground in one piece (its middle joints within 0.06 rad: the
  -- servos give under the humps' load, module 4 by 0.051 rad converged, at 20 substeps x 100
  -- iterations, and at the defaults since its contacts are solved on its own operator)
  expect(#world.components() == 4, "the chain holds together: " .. #world.components() .. " components")
  for i = 3, 10 do
    local want = 0.4 * math.sin((i - 1) * math.pi / 2)
    local got = chain[i]:joint_angle("pitch")
    expect(math.abs(got - want) < 0.06, string.format("chain module %d pitch %.3f, posed %.3f", i, got, want))
  end
end)
