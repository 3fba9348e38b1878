-- Cloth: a 1 x 1 m sheet (Bullet soft body, 32 x 32 nodes) falls over a four-module SuperBot
-- snake and a Wheelbot. The snake keeps crawling under it with a travelling wave; the Wheelbot
-- drives straight ahead (+x), drags the sheet along by friction for a while and comes out from
-- under it. Checks: the Wheelbot got out (clear of the sheet's far edge, the sheet no longer on
-- it), the snake is still covered, and the sheet stayed whole (no NaN, nothing below the ground).
--
--   ./build/rm3d run worlds/cloth.lua --png out/cloth.png --seconds 4
world.set{duration = 8}
world.ground{friction = 0.8}
world.camera{eye = {0.9, -1.25, 0.8}, target = {0.15, 0, 0.05}}

local snake = {}
for i = 1, 4 do
  snake[i] = world.spawn("superbot", {
    at = {-0.25, -0.3 + (i - 1) * 0.19, 0.043},
    rot = {0, 0, -math.pi / 2},
    name = "snake_" .. i,
    behavior = "behaviors/snake.lua",
    params = {index = i - 1, amplitude = 0.5},
  })
  if i > 1 then world.connect(snake[i - 1], "back", snake[i], "front") end
end
local car = world.spawn("wheelbot", {
  at = {0.15, 0, 0.04},
  name = "car",
  behavior = "behaviors/hold.lua",
  params = {velocities = {wheel_fl = 6, wheel_fr = 6, wheel_rl = 6, wheel_rr = 6}},
})

local sheet = world.cloth{
  corners = {{-0.55, -0.5, 0.3}, {0.45, -0.5, 0.3}, {0.45, 0.5, 0.3}, {-0.55, 0.5, 0.3}},
  resolution = {32, 32}, mass = 0.1, stiffness = 0.9, friction = 0.6, thickness = 0.01, color = {0.85, 0.35, 0.25},
}

-- Is any node of the sheet within `r` metres (horizontally) of p and above the ground there?
local function covered(p, r)
  for _, q in ipairs(sheet:positions()) do
    if (q.x - p.x) ^ 2 + (q.y - p.y) ^ 2 < r * r and q.z > 0.03 then return true end
  end
  return false
end

world.at(1, function()
  expect(covered(car:position(), 0.08), "the sheet lies on the Wheelbot at first")
end)
world.at(1.9, function()
  local b = sheet:bounds()
  expect(b and b.max.x > 0.47, string.format("the Wheelbot drags the sheet's far edge along (x=%.3f m, from 0.45 m)",
                                            b and b.max.x or 0 / 0))
end)
world.every(1, function(t)
  local b = sheet:bounds()
  expect(b ~= nil, "the sheet has no NaN node")
  if not b then return end
  print(string.format("t=%.0f s  car x=%.2f m  sheet x %.2f..%.2f  top z=%.3f m", t, car:position().x, b.min.x,
                      b.max.x, b.max.z))
end)
world.at(8, function()
  local b = sheet:bounds()
  local p = car:position()
  expect(p.x - 0.1 > b.max.x, string.format("the Wheelbot's tail (x=%.2f) is past the sheet's far edge (x=%.2f)",
                                            p.x - 0.1, b.max.x))
  expect(not covered(p, 0.08), "nothing of the sheet is on the Wheelbot")
  expect(b.min.z > -0.002, string.format("no node went through the ground (lowest z=%.4f m)", b.min.z))
  local under = 0
  for i = 1, 4 do
    if covered(snake[i]:position(), 0.06) then under = under + 1 end
  end
  expect(under >= 3, "the snake is still under the sheet (" .. under .. " of 4 modules covered)")
  for i = 1, 4 do expect(snake[i]:error() == nil, "snake module " .. i .. " ran without a fault") end
end)
