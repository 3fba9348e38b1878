-- A long chain lying still stays whole: 300 SuperBots docked in a straight line on the ground
-- (from the origin to 57 m along -x, servos holding their zero angles) for 2 s. Nothing breaks,
-- no dock carries 40 N (measured 15 N; a SuperBot dock holds 100 N), and no module moves 0.1 mm
-- (measured 0.04).
-- Before the contact anchors followed the position stabilisation's moves (contact_patches.cpp),
-- the anchors held every module against the microradian turns that close the chain's joint errors:
-- the friction added up along the chain and 71 docks broke in the second step (up to 127 N).
world.set{duration = 2}
world.ground{friction = 0.8}
local n = 300
local chain = require("snake_chain").build{n = n, type = "superbot", pose = "flat"}
local start, load, loadAt = {}, 0, 0
world.on_step(function(t)
  for i, m in ipairs(chain) do
    if not start[i] then start[i] = m:position() end
    local l = i < n and m:dock_load("back")
    if l and l.force > load then load, loadAt = l.force, t end
  end
end)
world.on_end(function()
  local broken, moved = 0, 0
  for _, e in ipairs(world.events()) do if e.event == "broken" then broken = broken + 1 end end
  for i, m in ipairs(chain) do
    local p, s = m:position(), start[i]
    moved = math.max(moved, math.sqrt((p.x - s.x) ^ 2 + (p.y - s.y) ^ 2 + (p.z - s.z) ^ 2))
  end
  expect(broken == 0, broken .. " connections broke")
  expect(load < 40, string.format("largest dock load %.1f N at t=%.2f s", load, loadAt))
  expect(moved < 1e-4, string.format("a module moved %.4f mm", moved * 1000))
  world.metric("largest_dock_load_n", load)
  world.metric("moved_mm", moved * 1000)
  log(string.format("largest dock load %.1f N at t=%.2f s, largest move %.4f mm", load, loadAt, moved * 1000))
end)
