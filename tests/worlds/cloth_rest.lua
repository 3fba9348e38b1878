-- Cloth dropped on a module rests on it: the nodes over the module's top stop on it (not inside
-- it, not through it), the rest drapes down to the ground, and the module is pressed down, not
-- thrown. Also a cloth on a static box lies on the box's top, and one falling 1.8 m onto a 2 cm
-- plate stops on it (no tunnelling at 2.5 cm a substep).
world.set{duration = 3}
world.ground{friction = 0.8}
local m = world.spawn("superbot", {at = {0, 0, 0.043}})
local c = world.cloth{corners = {{-0.3, -0.3, 0.35}, {0.3, -0.3, 0.35}, {0.3, 0.3, 0.35}, {-0.3, 0.3, 0.35}},
                      resolution = {25, 25}, mass = 0.05}
local box = world.box{size = {0.3, 0.3, 0.2}, at = {1.5, 0, 0.1}}
local c2 = world.cloth{corners = {{1.3, -0.2, 0.4}, {1.7, -0.2, 0.4}, {1.7, 0.2, 0.4}, {1.3, 0.2, 0.4}},
                       resolution = {17, 17}, mass = 0.03, color = {0.2, 0.5, 0.8}}
-- A 2 cm plate hit at 5.9 m/s (a 1.8 m fall): nodes move 2.5 cm a substep, the plate holds them.
world.box{size = {0.5, 0.5, 0.02}, at = {-1.5, 0, 0.3}}
local c3 = world.cloth{corners = {{-1.65, -0.15, 2.1}, {-1.35, -0.15, 2.1}, {-1.35, 0.15, 2.1}, {-1.65, 0.15, 2.1}},
                       resolution = {12, 12}, mass = 0.02}
local start = m:position()

-- Lowest node whose x, y lies within (dx, dy) of (x0, y0).
local function lowest_over(cloth, x0, y0, dx, dy)
  local low, n = math.huge, 0
  for _, p in ipairs(cloth:positions()) do
    if math.abs(p.x - x0) < dx and math.abs(p.y - y0) < dy then
      low = math.min(low, p.z)
      n = n + 1
    end
  end
  return low, n
end

world.at(3, function()
  local p = m:position()
  -- The SuperBot lying flat is 0.086 m tall (0.084 and the hulls' 1 mm margins); its middle
  -- 10 x 3 cm is its top.
  local low, n = lowest_over(c, p.x, p.y, 0.05, 0.015)
  expect(n >= 2, "some nodes lie over the module's top, got " .. n)
  expect(low > 0.080 and low < 0.105,
         string.format("cloth over the module rests on its top (lowest node z=%.4f m, top at 0.086 m)", low))
  local b = c:bounds()
  expect(b.min.z > -0.001 and b.min.z < 0.02, string.format("its edges reach the ground (z=%.4f m)", b.min.z))
  expect(b.max.z < 0.13, string.format("nothing floats above the module (z=%.4f m)", b.max.z))
  local moved = math.sqrt((p.x - start.x) ^ 2 + (p.y - start.y) ^ 2 + (p.z - start.z) ^ 2)
  expect(moved < 0.01, string.format("the module stays where it was (moved %.4f m)", moved))
  local low2, n2 = lowest_over(c2, 1.5, 0, 0.13, 0.13)
  expect(n2 > 50 and low2 > 0.2 and low2 < 0.215,
         string.format("cloth on the box lies on its top (%d nodes, lowest z=%.4f m, top at 0.2 m)", n2, low2))
  local b3 = c3:bounds()
  expect(b3.min.z > 0.31 and b3.max.z < 0.33,
         string.format("a sheet dropped from 2.1 m lies on a 2 cm plate, not through it (z %.4f..%.4f m)", b3.min.z,
                       b3.max.z))
  local v = c2:velocity()
  expect(math.sqrt(v.x ^ 2 + v.y ^ 2 + v.z ^ 2) < 0.02, "and rests there")
end)
