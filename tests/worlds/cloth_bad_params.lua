-- Bad cloth parameters raise errors that name the caller's file:line and say what was expected.
world.set{duration = 0.1}
local sq = {{0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}}
local function fails(opts, text, what)
  local ok, err = pcall(function() return world.cloth(opts) end)
  expect(not ok and tostring(err):find("cloth_bad_params.lua:", 1, true) and tostring(err):find(text, 1, true),
         what .. ": " .. tostring(err))
end
fails({corners = sq, resolution = {1, 10}}, "resolution must be 2..256 nodes a side", "resolution below 2")
fails({corners = sq, resolution = {300, 2}}, "resolution must be 2..256 nodes a side", "resolution above 256")
fails({corners = sq, resolution = {10}}, "option 'resolution' must be {nx, ny}", "resolution not a pair")
fails({corners = sq, mass = 0}, "mass must be positive", "zero mass")
fails({corners = sq, mass = -1}, "mass must be positive", "negative mass")
fails({corners = sq, stiffness = 0}, "stiffness must be in (0, 1]", "zero stiffness")
fails({corners = sq, stiffness = 1.5}, "stiffness must be in (0, 1]", "stiffness above 1")
fails({corners = {{0, 0, 1}, {1, 0, 1}, {1, 1, 1}}}, "got 3 points", "three corners")
fails({}, "option 'corners' must be 4 points", "no corners")
fails({corners = {{0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1}}}, "corner 4 is not {x, y, z}", "a short corner")
fails({corners = {{0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 0 / 0, 1}}}, "corner 4 has a coordinate that is not a finite",
      "a NaN corner")
fails({corners = {{0, 0, 1}, {1, 0, 1}, {2, 0, 1}, {3, 0, 1}}}, "corners must span an area", "corners in a line")
fails({corners = {{0, 0, 1}, {0, 0, 1}, {1, 1, 1}, {0, 1, 1}}}, "corners 1 and 2 must be apart", "equal corners")
fails({corners = sq, pinned = {5}}, "option 'pinned' must be a list of corner numbers (1..4); item 1 is 5",
      "pinned corner out of range")
fails({corners = sq, resolution = {4, 4}, pinned_nodes = {1, 17}},
      "option 'pinned_nodes' must be a list of node indices (1..16); item 2 is 17", "pinned node out of range")
fails({corners = sq, pinned = "all"}, "option 'pinned' must be a list of corner numbers", "pinned not a list")
fails({corners = sq, friction = 2}, "friction must be in [0, 1]", "friction above 1")
fails({corners = sq, thickness = 0}, "thickness must be 0.0001..0.1 m", "zero thickness")
fails({corners = sq, colour = {1, 0, 0}}, "unknown option 'colour'", "a misspelled key")

local c = world.cloth{corners = sq, resolution = {3, 3}}
local ok, err = pcall(function() return c:node(10) end)
expect(not ok and err:find("cloth_bad_params.lua:", 1, true) and err:find("node index must be 1..9", 1, true),
       "node index out of range: " .. tostring(err))
ok, err = pcall(function() c:pin(0) end)
expect(not ok and err:find("node index must be 1..9", 1, true), "pin index out of range: " .. tostring(err))
