-- Terrain: the ReMod3D paper's Fig. 1(g). A 5-module SuperBot snake crawls (+x) over a
-- heightfield made from a 30 x 30-pixel grayscale image (assets/terrain/hills_30.png, from
-- assets/terrain/make_terrain.lua), among 220 obstacles of various shapes: boxes, spheres,
-- cylinders, capsules and convex stones (dynamic: they settle, then sleep and cost the step
-- nothing until something touches them), static pillars, and one static concave triangle mesh
-- (a bowl, assets/meshes/bowl.obj, with balls in it). Beside the terrain is the basin the
-- paper fills with 1000 fluid particles (world.fluid, 4 cm apart).
-- Prints the head's progress every second. Try: --param obstacles=500, --param height=0.2.

local kSize, kHeight = tonumber(args.size) or 6.0, tonumber(args.height) or 0.35  -- m: the terrain's extent and relief
local obstacles = tonumber(args.obstacles) or 220
local kRough = tonumber(args.rough) or 0.004  -- m: rolling resistance of the stones and balls (grass)

world.set{dt = 1 / 60, duration = 20}
world.ground{friction = 0.8}
local hf = world.heightfield{image = "assets/terrain/hills_30.png", size = {kSize, kSize}, height = kHeight,
                             at = {0, 0, 0}, friction = 0.9}

-- The snake: five SuperBots docked front to back, head towards +x, along y = 0 from x = -1.2.
local n = 5
local function highest(x0, x1, y)  -- the terrain's highest point under a stretch of the chain
  local h = 0
  for x = x0, x1, 0.05 do h = math.max(h, hf:height_at(x, y) or 0) end
  return h
end
local lift = highest(-1.2 - n * 0.19, -1.0, 0) + 0.06
local chain = {}
for i = 1, n do
  chain[i] = world.spawn("superbot", {
    at = {-1.2 - (i - 1) * 0.19, 0, lift},
    name = "snake_" .. i,
    behavior = "behaviors/snake.lua",
    params = {index = i - 1},
  })
  if i > 1 then world.connect(chain[i - 1], "back", chain[i], "front") end
end

-- Obstacles, scattered over the terrain off the snake's lane (|y| < 0.45), dropped onto it. The
-- stones and balls roll as on grass (rolling_friction), so they come to rest on the slopes.
local function rand(a, b) return a + (b - a) * math.random() end
local placed, spots = 0, {}
-- Obstacles at least kGap apart: closer ones touch or nearly (Bullet merges bodies whose bounding
-- boxes overlap into one "island", which sleeps only when all of it is still).
local kGap = tonumber(args.gap) or 0.3
local function free(x, y)
  for _, p in ipairs(spots) do
    if (p[1] - x) ^ 2 + (p[2] - y) ^ 2 < kGap ^ 2 then return false end
  end
  return true
end
for _ = 1, 100 * obstacles do
  if placed >= obstacles then break end
  local x, y = rand(-kSize / 2 + 0.1, kSize / 2 - 0.1), rand(-kSize / 2 + 0.1, kSize / 2 - 0.1)
  if math.abs(y) > 0.45 and free(x, y) then
    spots[#spots + 1] = {x, y}
    placed = placed + 1
    local ground = hf:height_at(x, y)
    local kind = placed % 6
    local yaw = rand(0, math.pi)
    if kind == 0 then
      local s = {rand(0.04, 0.12), rand(0.04, 0.12), rand(0.03, 0.08)}
      world.box{size = s, at = {x, y, ground + s[3] / 2 + 0.02}, rot = {0, 0, yaw}, mass = 0.2, rolling_friction = kRough}
    elseif kind == 1 then
      local r = rand(0.02, 0.05)
      world.sphere{radius = r, at = {x, y, ground + r + 0.02}, mass = 0.1, rolling_friction = kRough}
    elseif kind == 2 then
      local r, l = rand(0.02, 0.04), rand(0.04, 0.1)
      world.cylinder{radius = r, length = l, at = {x, y, ground + l / 2 + 0.02}, mass = 0.1, rolling_friction = kRough}
    elseif kind == 3 then
      local r, l = rand(0.015, 0.03), rand(0.04, 0.1)
      world.capsule{radius = r, length = l, at = {x, y, ground + r + 0.02}, rot = {0, math.pi / 2, yaw}, mass = 0.1, rolling_friction = kRough}
    elseif kind == 4 then
      world.mesh{file = "assets/meshes/rock.obj", scale = rand(0.8, 1.6), at = {x, y, ground + 0.07},
                 rot = {0, 0, yaw}, mass = 0.15, rolling_friction = kRough}
    else  -- static pillars and boulders
      if placed % 12 == 5 then
        world.cylinder{radius = 0.05, length = 0.3, at = {x, y, ground + 0.13}}
      else
        world.box{size = {0.15, 0.1, 0.12}, at = {x, y, ground + 0.04}, rot = {0, 0, yaw}}
      end
    end
  end
end

-- One static concave triangle mesh: a bowl beside the terrain, with balls in it.
world.mesh{file = "assets/meshes/bowl.obj", concave = true, at = {-kSize / 2 - 0.6, 1.0, 0}}
for k = 0, 4 do
  world.sphere{radius = 0.04, mass = 0.1, at = {-kSize / 2 - 0.6 + 0.06 * math.cos(k * 1.3), 1.0 + 0.06 * math.sin(k * 1.3),
                                                0.1 + 0.1 * k}}
end

-- ---- The fluid pool (the paper's 1000 particles) ----
-- A basin on the ground beside the terrain, inner size 0.8 x 0.8 m, walls 0.12 m high, filled
-- with 19 x 19 x 3 = 1083 fluid particles.
local kPool = {x = kSize / 2 + 0.6, y = 0, half = 0.4, wall = 0.03, h = 0.12}
for _, w in ipairs{{kPool.half + kPool.wall / 2, 0, kPool.wall, 2 * kPool.half + 2 * kPool.wall},
                   {-kPool.half - kPool.wall / 2, 0, kPool.wall, 2 * kPool.half + 2 * kPool.wall},
                   {0, kPool.half + kPool.wall / 2, 2 * kPool.half, kPool.wall},
                   {0, -kPool.half - kPool.wall / 2, 2 * kPool.half, kPool.wall}} do
  world.box{size = {w[3], w[4], kPool.h}, at = {kPool.x + w[1], kPool.y + w[2], kPool.h / 2}}
end
local pool = world.fluid{min = {kPool.x - 0.38, kPool.y - 0.38, 0.01}, max = {kPool.x + 0.38, kPool.y + 0.38, 0.13},
                         spacing = 0.04, density = 1000}
world.on_end(function()
  local inside = pool:count_in({kPool.x - kPool.half, kPool.y - kPool.half, 0}, {kPool.x + kPool.half, kPool.y + kPool.half, kPool.h})
  world.metric("pool_particles", inside)
  expect(inside >= 0.95 * pool:count(), string.format("the pool should keep its water: %d of %d particles in the basin", inside, pool:count()))
end)

world.camera{eye = {-3.3, -2.9, 1.25}, target = {-0.5, 0.5, 0.1}, fov = 50}

local head = chain[1]
local start = head:position()
world.every(1, function(t)
  local p = head:position()
  print(string.format("t=%4.1f s  head x=%+.3f m  moved %.3f m", t, p.x, p.x - start.x))
end)

world.on_end(function(t)
  if t <= 0 then return end
  world.metric("speed_m_s", (head:position().x - start.x) / t)
  world.metric("pieces", #world.components())
end)
