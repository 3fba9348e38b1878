-- Raw sensors: the accelerometer reads gravity at rest within 0.05 m/s^2, the gyro reads no
-- rotation, position and orientation match the module, contact sees the ground, a dock's
-- IR proximity reads the distance to a facing free dock within 0.1 m (nil beyond) and its bearing
-- the direction to it in the dock's frame (x out of the face, z its up, y = z x x), and
-- injected faults kill a sensor, stall a joint and stop a dock latching.
world.set{duration = 2}
world.ground{}
local rest = world.spawn("superbot", {at = {0, 0, 0.043}, behavior = "behaviors/hold.lua"})
-- Two pairs in the air, docks facing: 5 cm apart (seen, beyond the 3 cm capture) and 15 cm.
local a1 = world.spawn("superbot", {at = {2, 0, 1}, fixed = true})
local b1 = world.spawn("superbot", {at = {2 - 0.19 - 0.05, 0, 1}, fixed = true})
local a2 = world.spawn("superbot", {at = {2, 1, 1}, fixed = true})
local b2 = world.spawn("superbot", {at = {2 - 0.19 - 0.15, 1, 1}, fixed = true})
-- A pair off to one side: b3's front dock 4 cm out from a3's back dock and 3 cm to world +y
-- (the back dock's frame: x is world -x, y is world -y): bearing (0.8, -0.6, 0) at 5 cm.
local a3 = world.spawn("superbot", {at = {2, 2, 1}, fixed = true})
local b3 = world.spawn("superbot", {at = {2 - 0.19 - 0.04, 2.03, 1}, fixed = true})
local stall = world.spawn("superbot", {at = {0, 1, 0.043}, behavior = "behaviors/sweep.lua"})
local reader = world.spawn("superbot", {at = {0, -1, 0.043}, behavior = "../behaviors/sensor_reader.lua"})

world.at(1, function()
  local acc = rest:sensor("accelerometer")
  local err = math.sqrt(acc.x ^ 2 + acc.y ^ 2 + (acc.z - 9.81) ^ 2)
  -- the module rests slightly tilted on its protruding back bracket: compare magnitudes too
  local mag = math.sqrt(acc.x ^ 2 + acc.y ^ 2 + acc.z ^ 2)
  expect(math.abs(mag - 9.81) < 0.05, string.format("accelerometer magnitude %.4f, expected 9.81", mag))
  local q = rest:orientation()
  local up = {2 * (q.x * q.z - q.w * q.y), 2 * (q.y * q.z + q.w * q.x), 1 - 2 * (q.x ^ 2 + q.y ^ 2)}  -- world z in module frame
  local want = {up[1] * 9.81, up[2] * 9.81, up[3] * 9.81}
  local d = math.sqrt((acc.x - want[1]) ^ 2 + (acc.y - want[2]) ^ 2 + (acc.z - want[3]) ^ 2)
  expect(d < 0.05, string.format("accelerometer %.4f m/s^2 from gravity in the module frame", d))
  local g = rest:sensor("gyro")
  expect(math.abs(g.x) + math.abs(g.y) + math.abs(g.z) < 0.01, string.format("gyro reads no rotation at rest: %.4f %.4f %.4f", g.x, g.y, g.z))
  local p, mp = rest:sensor("position"), rest:position()
  expect(math.abs(p.x - mp.x) + math.abs(p.y - mp.y) + math.abs(p.z - mp.z) < 1e-9, "position sensor = module position")
  expect(rest:sensor("contact:back_outer") == true, "the back bracket touches the ground")
  expect(rest:sensor("joint:pitch") == rest:joint_angle("pitch"), "joint sensor = joint angle")
  local s1 = a1:sensor("dock:back")
  expect(s1.enabled and not s1.engaged, "dock sensor state")
  expect(s1.proximity ~= nil and math.abs(s1.proximity - 0.05) < 0.001,
         "proximity 5 cm, got " .. tostring(s1.proximity))
  expect(a2:sensor("dock:back").proximity == nil, "nothing within 10 cm: nil")
  local bb = s1.bearing
  expect(bb ~= nil and math.abs(bb.x - 1) < 1e-3 and math.abs(bb.y) < 1e-3 and math.abs(bb.z) < 1e-3,
         "bearing of a facing dock: (1, 0, 0), got " .. (bb and string.format("(%.4f, %.4f, %.4f)", bb.x, bb.y, bb.z) or "nil"))
  expect(a2:sensor("dock:back").bearing == nil, "nothing within 10 cm: no bearing")
  local s3 = a3:sensor("dock:back")
  local b = s3.bearing
  expect(math.abs(s3.proximity - 0.05) < 1e-3, "the side pair is 5 cm apart, got " .. tostring(s3.proximity))
  expect(b ~= nil and math.abs(b.x - 0.8) < 1e-3 and math.abs(b.y + 0.6) < 1e-3 and math.abs(b.z) < 1e-3,
         "bearing to a dock off to one side: (0.8, -0.6, 0), got " ..
         (b and string.format("(%.4f, %.4f, %.4f)", b.x, b.y, b.z) or "nil"))
  expect(b[1] == b.x and b[2] == b.y and b[3] == b.z, "a bearing is a vector: [1..3] and x, y, z")
  rest:inject_fault{sensor = "accelerometer"}
  stall:inject_fault{joint = "pitch"}
end)
local stalledAt
world.at(1.05, function()
  expect(rest:sensor("accelerometer") == nil, "a dead sensor reads nil")
  stalledAt = stall:joint_angle("pitch")
end)
world.at(1.9, function()
  expect(reader:error() == nil and not reader:dock_state("up").enabled,
         "a behaviour read its sensors: " .. tostring(reader:error()))
  expect(math.abs(stall:joint_angle("pitch") - stalledAt) < 0.02, "a stalled joint stays where it failed")
  expect(math.abs(stall:joint_angle("roll")) < 0.05, "...")
end)
