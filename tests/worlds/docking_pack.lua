-- A packed lattice docking at run time: 36 SuperBots in a 6 x 6 grid float in zero gravity,
-- every dock enabled, their front and back faces 10 mm apart and their side faces 28 mm apart
-- (inside the 30 mm capture radius). Capture joints draw every facing pair together and each
-- latches; the side connections close loops through the rows already docked front to back, so
-- the pack ends as one lattice of 25 closed loops. Nothing breaks (each latch merges the two
-- links; the loops' rows are solved through the tree, and their nearly redundant directions,
-- two modules' pitch axes side by side being almost one line, are damped rather than inverted
-- exactly: a pack of 100 diverged before), nothing drifts away and the lattice comes to rest.
world.set{gravity = {0, 0, 0}, duration = 3}
local side, dx, dy = 6, 0.20, 0.114
local modules = {}
for i = 0, side * side - 1 do
  modules[#modules + 1] = world.spawn("superbot", {at = {-(i % side) * dx, (i // side) * dy, 0}})
end
local function centre()
  local c = {x = 0, y = 0, z = 0}
  for _, m in ipairs(modules) do
    local p = m:position()
    c.x, c.y, c.z = c.x + p.x / #modules, c.y + p.y / #modules, c.z + p.z / #modules
  end
  return c
end
local start = centre()
world.on_end(function()
  local engaged, broken, stalled, last = 0, 0, 0, 0
  for _, e in ipairs(world.events()) do
    if e.event == "engaged" then engaged, last = engaged + 1, math.max(last, e.time) end
    if e.event == "broken" then broken = broken + 1 end
    if e.event == "stalled" then stalled = stalled + 1 end
  end
  local pairs_ = 2 * side * (side - 1)
  world.metric("latched", engaged)
  world.metric("broken", broken)
  world.metric("last_latch_s", last)
  expect(engaged == pairs_, string.format("all %d facing pairs latched (%d)", pairs_, engaged))
  expect(broken == 0 and stalled == 0, string.format("nothing broke or stalled (%d broken, %d stalled)", broken, stalled))
  expect(last < 1.5, string.format("the last latch came at %.2f s", last))
  expect(#world.components() == 1, "the pack is one lattice: " .. #world.components() .. " pieces")
  local c = centre()
  local moved = math.sqrt((c.x - start.x) ^ 2 + (c.y - start.y) ^ 2 + (c.z - start.z) ^ 2)
  world.metric("centre_moved_mm", moved * 1000)
  expect(moved < 0.005, string.format("the pack's centre stayed (moved %.2f mm)", moved * 1000))
  local fastest = 0
  for _, m in ipairs(modules) do
    local v = m:velocity()
    fastest = math.max(fastest, math.sqrt(v.x ^ 2 + v.y ^ 2 + v.z ^ 2))
  end
  world.metric("fastest_mps", fastest)
  expect(fastest < 0.01, string.format("the lattice is at rest (fastest module %.4f m/s)", fastest))
end)
