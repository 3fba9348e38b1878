-- Cloth pinned at two corners hangs without exploding: the pinned corners stay put, every node
-- stays finite and within the sheet's reach of the pins, the lowest edge hangs about the sheet's
-- length below them, and the sheet comes to rest. Then the pins let go and it falls
-- in a heap on the ground, not through it.
world.set{duration = 6}
world.ground{}
local top = 1.2
local c = world.cloth{corners = {{-0.5, 0, top}, {0.5, 0, top}, {0.5, 1, top}, {-0.5, 1, top}},
                      resolution = {21, 21}, mass = 0.2, stiffness = 0.9, pinned = {1, 2}}
expect(c:count() == 441, "21 x 21 nodes, got " .. c:count())
local nx, ny = c:resolution()
expect(nx == 21 and ny == 21, "resolution 21 x 21")
expect(c:pinned(1) and c:pinned(21) and not c:pinned(441), "corners 1 and 2 are nodes 1 and 21, pinned")

local worst = 0  -- largest distance of any node from the pins' midpoint, over the run
world.on_step(function(t)
  if t > 4 then return end
  local b = c:bounds()
  expect(b ~= nil, "no node is NaN")
  if not b then world.stop() return end
  for _, p in ipairs({b.min, b.max}) do
    worst = math.max(worst, math.abs(p.x), math.abs(p.y), math.abs(p.z - top))
  end
end)

world.at(4, function()
  expect(worst < 1.1, string.format("nodes stay within the sheet's reach of the pins (%.3f m)", worst))
  local a, b = c:node(1), c:node(21)
  expect(math.abs(a.x + 0.5) + math.abs(a.y) + math.abs(a.z - top) < 1e-5, "pinned corner 1 stays put")
  expect(math.abs(b.x - 0.5) + math.abs(b.y) + math.abs(b.z - top) < 1e-5, "pinned corner 2 stays put")
  local bb = c:bounds()
  local drop = top - bb.min.z
  expect(drop > 0.95 and drop < 1.08,
         string.format("the free edge hangs about 1 m below the pins (%.3f m; a little stretch)", drop))
  expect(math.abs(bb.min.x) < 0.52 and bb.max.x < 0.52, "the sheet stays as wide as it is")
  expect(math.abs(bb.min.y) < 0.15 and bb.max.y < 0.15, "and hangs in the plane of the pins")
  local v = c:velocity()
  expect(math.sqrt(v.x ^ 2 + v.y ^ 2 + v.z ^ 2) < 0.05, "it has (nearly) come to rest")
  c:unpin(1)
  c:unpin(21)
end)

world.at(6, function()
  local bb = c:bounds()
  expect(bb.max.z < 0.25, string.format("let go, it lies in folds on the ground (top at %.3f m)", bb.max.z))
  expect(bb.min.z > -0.001, string.format("and not through it (%.4f m)", bb.min.z))
end)
