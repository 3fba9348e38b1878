-- The magnet's torque turns two docks towards each other: in zero gravity, a SuperBot 20 deg off
-- in yaw with its front dock 15 mm from another's back dock turns into line (the yaw between the
-- two falls) and latches. Measured: yaw 20 -> 15.7 deg after 0.05 s, latched at 0.117 s; with the
-- torque's sign the other way round (as it was before this test), 20 -> 19.3 deg and 0.150 s.
world.docks{capture = "magnet"}  -- the force magnet (capture joints: tests/worlds/docking_ground.lua)
world.set{gravity = {0, 0, 0}, duration = 0.5}
local yaw = math.rad(20)
local a = world.spawn("superbot", {at = {0, 0, 0}, name = "a"})
local b = world.spawn("superbot", {at = {-0.19 - 0.095 * (1 - math.cos(yaw)) - 0.015, -0.095 * math.sin(yaw), 0},
                                   rot = {0, 0, yaw}, name = "b"})
local function yawOf(m)
  local q = m:orientation()
  return 2 * math.atan(q.z, q.w)
end
local latched, at005
world.on_step(function(t)
  if not at005 and t >= 0.05 - 1e-9 then at005 = math.deg(yawOf(b) - yawOf(a)) end
  if not latched and a:dock_state("back").engaged then latched = t end
end)
world.on_end(function()
  log(string.format("yaw after 0.05 s %.2f deg, latched at %s s", at005, tostring(latched)))
  expect(at005 < 17.5, string.format("the magnet should turn the docks towards each other: yaw %.2f deg after 0.05 s", at005))
  expect(latched and latched < 0.14, "the pair latches within 0.14 s, latched at " .. tostring(latched))
end)
