-- Run-time docking: two SuperBots pushed towards each other dock when their faces are aligned
-- (the magnet pulls them in and latches; on_dock reports "engaged" to both behaviours), and do
-- not dock when one is pitched 45 degrees (beyond the 30 degree capture angle). A pair 15
-- degrees off in yaw is turned into line by the magnet and docks.
world.docks{capture = "magnet"}  -- the force magnet (capture joints: tests/worlds/docking_ground.lua)
world.set{gravity = {0, 0, 0}, duration = 3}
local watcher = "../behaviors/dock_watcher.lua"
local function pair(y, pitch, yaw)
  local a = world.spawn("superbot", {at = {0, y, 0}, behavior = watcher})
  local b = world.spawn("superbot", {at = {-0.19 - 0.10, y, 0}, rot = {0, pitch, yaw}, behavior = watcher})
  return a, b
end
local a1, b1 = pair(0, 0, 0)
local a2, b2 = pair(1, math.rad(45), 0)
local a3, b3 = pair(2, 0, math.rad(15))
-- Drive b towards a until they are within a few centimetres, then let the magnet act.
world.on_step(function(t)
  for _, p in ipairs({{a1, b1}, {a2, b2}, {a3, b3}}) do
    local a, b = p[1], p[2]
    local gap = a:dock_position("back").x - b:dock_position("front").x
    if t < 1 and gap > 0.02 then b:push({1.0, 0, 0}) end
  end
end)
world.at(2.5, function()
  local s1 = a1:dock_state("back")
  expect(s1.engaged and s1.peer_module == b1.id and s1.peer_dock == "front", "aligned pair docked back-front")
  local d = a1:dock_position("back")
  local e = b1:dock_position("front")
  local gap = math.sqrt((d.x - e.x) ^ 2 + (d.y - e.y) ^ 2 + (d.z - e.z) ^ 2)
  expect(gap < 0.001, string.format("docked faces %.4f m apart", gap))
  expect(math.abs(a1:joint_angle("pitch") - 0.5) < 0.05 and math.abs(b1:joint_angle("pitch") - 0.5) < 0.05,
         "both behaviours heard on_dock 'engaged'")
  expect(not a2:dock_state("back").engaged and not b2:dock_state("front").engaged, "45 degrees off: no docking")
  expect(a3:dock_state("back").engaged, "15 degrees off: the magnet aligned them and they docked")
  for _, m in ipairs(world.modules()) do expect(m:error() == nil, tostring(m:error())) end
end)
