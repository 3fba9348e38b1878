-- Two stock Wheelbots drive head on and dock front to front: their wheels stay behind the dock
-- faces, so the docks come within latching distance (before, the wheels stuck out 1 cm past the
-- docks and touched first, and capture stalled at 19 mm).
world.set{duration = 3}
world.ground{friction = 0.8}
local a = world.spawn("wheelbot", {at = {-0.2, 0, 0.045}, name = "a", behavior = "../behaviors/drive_forward.lua"})
local b = world.spawn("wheelbot", {at = {0.2, 0, 0.045}, rot = {0, 0, math.pi}, name = "b",
                                   behavior = "../behaviors/drive_forward.lua"})
local engaged_at
world.on_step(function(t)
  if not engaged_at and a:dock_state("front").engaged then engaged_at = t end
end)
world.on_end(function(t)
  local s = a:dock_state("front")
  expect(s.engaged and s.peer_module == b.id and s.peer_dock == "front",
         "the two Wheelbots docked front to front (a's front dock: engaged=" .. tostring(s.engaged) .. ")")
  expect(engaged_at ~= nil and engaged_at < 2.5, "docked within 2.5 s, at " .. tostring(engaged_at))
  local pa, pb = a:dock_position("front"), b:dock_position("front")
  local gap = math.sqrt((pa.x - pb.x) ^ 2 + (pa.y - pb.y) ^ 2 + (pa.z - pb.z) ^ 2)
  expect(gap < 0.001, string.format("dock faces mate (gap %.4f m)", gap))
end)
