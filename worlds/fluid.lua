-- The ReMod3D paper's Fig. 7: 40,000 fluid particles (position-based fluids, world.fluid) in a
-- tank with modules in it. The water starts as a block at one end and breaks over a two-module
-- SuperBot snake crawling on the floor at the other end; a light box (half the water's density)
-- floats on the surface. Particles and bodies push each other both ways.
--
--   ./build/rm3d run worlds/fluid.lua --seconds 6 [--threads 2] [--param particles=10000]
--
-- The checks: no particle is lost, every one stays in the tank, and the box floats.
world.set{duration = 6}
world.ground{friction = 1.0}

local n = tonumber(args.particles or 40000)
local L, W, H, T = 1.2, 0.6, 1.0, 0.3 -- tank inside, wall height and thickness (the wave climbs the far wall)
world.box{size = {L + 2 * T, T, H}, at = {0, W / 2 + T / 2, H / 2}}
world.box{size = {L + 2 * T, T, H}, at = {0, -W / 2 - T / 2, H / 2}}
world.box{size = {T, W, H}, at = {L / 2 + T / 2, 0, H / 2}}
world.box{size = {T, W, H}, at = {-L / 2 - T / 2, 0, H / 2}}

-- A block 0.5 m long, the tank's width, 0.35 m high, at the spacing that gives n particles.
local bx, bz = 0.5, 0.35
local spacing = (bx * W * bz / n) ^ (1 / 3)
local water = world.fluid{min = {-L / 2, -W / 2, 0}, max = {-L / 2 + bx, W / 2, bz}, spacing = spacing}
local count = water:count()

local head = world.spawn("superbot", {at = {0.35, 0, 0.043}, behavior = "behaviors/snake.lua", params = {index = 0}})
local tail = world.spawn("superbot", {at = {0.16, 0, 0.043}, behavior = "behaviors/snake.lua", params = {index = 1}})
world.connect(tail, "back", head, "front")
local float = world.box{size = {0.12, 0.12, 0.12}, at = {-0.4, 0.1, 0.5}, mass = 500 * 0.12 ^ 3}
world.camera{eye = {0.5, -1.1, 3.2}, target = {0, 0, 0}}

world.every(1, function(t)
  local lo, hi = water:bounds()
  print(string.format("t=%.0f s  %d particles, %.2f..%.2f m in x, top %.3f m  box z=%.3f  snake x=%+.3f", t,
                      water:count(), lo[1], hi[1], hi[3], float:position()[3], head:position().x))
end)

world.on_end(function(t)
  expect(water:count() == count, "every particle is still there")
  local inside = water:count_in({-L / 2, -W / 2, 0}, {L / 2, W / 2, H + 1})
  expect(inside == count, string.format("the water stays in the tank: %d of %d inside", inside, count))
  if t > 2.5 then expect(float:position()[3] > 0.1, "the light box floats") end
end)
