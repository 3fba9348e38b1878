-- Breakage (the paper's Fig. 6): 45 SuperBots docked in a 9 x 5 grid float in zero gravity and
-- are hit by five heavy spheres. Docks carry at most 100 N and 10 N m (the SuperBot type's
-- strength); where an impact loads a connection beyond that, it breaks ("broken" events with
-- the measured load in the JSON summary). The connections that hold keep their modules exactly
-- together, and nothing explodes. On the exact solver (the default) 25 of the 76 connections hold:
-- its rigid hinges pass each impact's shear on to the neighbours at once, whose docks then carry
-- it (59 hold on "pgs", whose softer joints spread it over several steps; 26 at 8 substeps). The
-- grid's loops are nearly redundant where two modules' pitch axes line up, and the solver damps
-- those directions (docs/physics.md, "Lattices"); solved exactly, only 11 held.
world.set{gravity = {0, 0, 0}, duration = 3}
local rows, cols = 5, 9
local grid = {}
for r = 1, rows do
  grid[r] = {}
  for c = 1, cols do
    grid[r][c] = world.spawn("superbot", {at = {-(c - 1) * 0.19, (r - 1) * 0.086, 1}, name = string.format("m%d_%d", r, c)})
    if c > 1 then world.connect(grid[r][c - 1], "back", grid[r][c], "front") end
  end
  if r > 1 then
    for c = 1, cols do world.connect(grid[r - 1][c], "left", grid[r][c], "right") end
  end
end
local made = #world.modules() > 0 and #world.components() == 1
local original = {}  -- peer of each dock at the start: connections made by world.connect
for r = 1, rows do
  for c = 1, cols do
    for _, d in ipairs({"back", "left"}) do
      local s = grid[r][c]:dock_state(d)
      if s.engaged then original[grid[r][c].name .. d] = s.peer_module end
    end
  end
end
-- Five 5 kg balls thrown down onto the grid at 3 m/s.
local targets = {{1, 2}, {3, 5}, {5, 8}, {2, 8}, {4, 2}}
for _, t in ipairs(targets) do
  local p = grid[t[1]][t[2]]:position()
  world.sphere{radius = 0.06, mass = 5, at = {p.x, p.y, 1.4}, velocity = {0, 0, -3}}
end

world.at(2.9, function()
  expect(made, "the grid starts as one piece")
  local broke = {}
  for _, e in ipairs(world.events()) do
    if e.event == "broken" then
      broke[e.module_a .. e.dock_a] = true
      broke[e.module_b .. e.dock_b] = true
    end
  end
  local graph = world.graph("json")
  local connections = select(2, graph:gsub('%["?%d+"?,"%a+",%d+,"%a+"%]', ""))
  local total = (rows * (cols - 1)) + ((rows - 1) * cols)
  print(string.format("%d of %d connections hold, %d pieces", connections, total, #world.components()))
  expect(connections < total, "some connections broke")
  expect(connections > 0, "some connections held")
  -- Every connection that broke carried more than the dock's strength.
  for _, e in ipairs(world.events()) do
    if e.event == "broken" then
      expect(e.force > 100 or e.torque > 10,
             string.format("%d.%s broke at %.1f N and %.2f N m, within its strength (100 N, 10 N m)",
                           e.module_a, e.dock_a, e.force, e.torque))
    end
  end
  for r = 1, rows do
    for c = 1, cols do
      local m = grid[r][c]
      local p = m:position()
      expect(p.x == p.x and p.y == p.y and p.z == p.z and math.abs(p.z) < 100, m.name .. " has a finite position")
      for _, d in ipairs({"back", "left"}) do
        local s = m:dock_state(d)
        if s.engaged then
          -- Original connections that never broke are exact (docked links are one rigid body);
          -- pieces that met again may have latched anywhere within the 4 mm latch distance.
          local a, b = m:dock_position(d), world.module(s.peer_module):dock_position(s.peer_dock)
          local gap = math.sqrt((a.x - b.x) ^ 2 + (a.y - b.y) ^ 2 + (a.z - b.z) ^ 2)
          local limit = (original[m.name .. d] == s.peer_module and not broke[m.id .. d]) and 0.001 or 0.0045
          expect(gap < limit, string.format("%s %s: held connection %.4f m apart", m.name, d, gap))
        end
      end
    end
  end
end)
