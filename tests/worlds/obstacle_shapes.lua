-- Obstacle shapes beyond obstacles.lua, and sleeping: a capsule lying on its side rests at its
-- radius and a static one stays put; a ball dropped into a static concave bowl (world.mesh with
-- concave = true) comes to rest at the bottom, while one dropped on the same mesh as a convex
-- hull rests on the hull's flat top at the rim; 300 small dynamic obstacles of five shapes
-- (boxes, spheres, cylinders, capsules, convex stones) all fall asleep; a sleeping box wakes and
-- moves when a Wheelbot drives into it.
world.set{duration = 6}
world.ground{friction = 0.8}

local kCapsuleR, kCapsuleL = 0.03, 0.12
local lying = world.capsule{radius = kCapsuleR, length = kCapsuleL, at = {0, -1, 0.1}, rot = {0, math.pi / 2, 0},
                            mass = 0.2}
local pillar = world.capsule{radius = 0.05, length = 0.3, at = {0.4, -1, 0.2}}  -- static

-- The bowl's flat bottom (0.1 m in radius) is at its origin; the rim is 0.283 m up.
world.mesh{file = "assets/meshes/bowl.obj", concave = true, at = {-1, 1, 0}}
local inBowl = world.sphere{radius = 0.05, mass = 0.2, at = {-1, 1, 0.5}}
world.mesh{file = "assets/meshes/bowl.obj", at = {0, 1, 0}}  -- its convex hull: a solid with a flat top
local onHull = world.sphere{radius = 0.05, mass = 0.2, at = {0, 1, 0.5}}

-- 300 small obstacles on a 20 x 15 grid, just above the ground, in five shapes.
local crowd = {}
for i = 0, 299 do
  local x, y = 2 + (i % 20) * 0.15, -1 + (i // 20) * 0.15
  local kind = i % 5
  local b
  if kind == 0 then
    b = world.box{size = {0.06, 0.05, 0.04}, at = {x, y, 0.025}, mass = 0.1}
  elseif kind == 1 then
    b = world.sphere{radius = 0.03, at = {x, y, 0.035}, mass = 0.1}
  elseif kind == 2 then
    b = world.cylinder{radius = 0.03, length = 0.05, at = {x, y, 0.03}, mass = 0.1}
  elseif kind == 3 then
    b = world.capsule{radius = 0.02, length = 0.06, at = {x, y, 0.025}, rot = {math.pi / 2, 0, 0}, mass = 0.1}
  else
    b = world.mesh{file = "assets/meshes/rock.obj", at = {x, y, 0.035}, mass = 0.1}
  end
  crowd[#crowd + 1] = b
end

-- A box in a Wheelbot's way; the Wheelbot starts driving at 3 s, when the box is asleep.
local target = world.box{size = {0.1, 0.1, 0.1}, at = {-1, -1, 0.05}, mass = 0.3}
world.spawn("wheelbot", {name = "pusher", at = {-1.4, -1, 0.041}, behavior = "../behaviors/drive_forward.lua",
                         params = {start = 3, speed = 6}})
local targetAsleepAt3, targetAt3

world.at(2.9, function()
  targetAsleepAt3 = target:sleeping()
  targetAt3 = target:position()
end)

world.at(4, function()
  local function near(v, want, what)
    expect(math.abs(v - want) < 0.002, string.format("%s: %.4f, expected %.4f", what, v, want))
  end
  near(lying:position().z, kCapsuleR, "the lying capsule's height")
  local p = pillar:position()
  expect(math.abs(p.x - 0.4) + math.abs(p.y + 1) + math.abs(p.z - 0.2) < 1e-6, "the static capsule stays put")
  expect(pillar:sleeping(), "a static body counts as asleep")
  local b = inBowl:position()
  near(b.z, 0.05, "the ball in the concave bowl rests at the bottom")
  expect(math.abs(b.x + 1) < 0.01 and math.abs(b.y - 1) < 0.01, "the ball is at the bowl's centre")
  expect(onHull:position().z > 0.33, string.format("the ball on the convex hull rests on its top (z=%.3f)",
                                                   onHull:position().z))
  local asleep, worst = 0, 0
  for _, o in ipairs(crowd) do
    if o:sleeping() then asleep = asleep + 1 end
    local v = o:velocity()
    worst = math.max(worst, math.sqrt(v.x ^ 2 + v.y ^ 2 + v.z ^ 2))
  end
  expect(asleep == 300, string.format("%d of 300 obstacles asleep", asleep))
  expect(worst == 0, string.format("sleeping obstacles are still (fastest %.2g m/s)", worst))
  expect(targetAsleepAt3, "the box is asleep before the Wheelbot sets off")
end)

world.at(6, function()
  local q = target:position()
  local moved = q.x - targetAt3.x
  expect(moved > 0.1, string.format("the Wheelbot woke the box and pushed it %.3f m", moved))
end)
