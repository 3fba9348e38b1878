-- A walker built directly walks as the other ways of solving say it should (docs/benchmarks.md,
-- "Chains on their own operator by default"). The 8-module walker of worlds/snake_walker_snake.lua:
-- a chain of four SuperBots with a one-module leg on each side of the second and the fourth,
-- trotting (lua/walker_gait.lua, without its steering), and the same robot standing. Measured on
-- 2026-12-07, the head's way in 20 s: on its contacts' own operator (the default) 0.230 m at one
-- substep x 15 iterations, 0.221 at 20 x 100; Bullet's own solver ("pgs") 0.203 at 20 x 100 and
-- 0.223 at 40 x 200; with the tree's contacts swept instead 0.466, 0.313 and 0.356, the odd ones out
-- (the sweeps move a servo-held module as one body). Standing, the body is 0.110 m up either way
-- and stays within 0.5 mm, as bodies at rest do (tests/worlds/rest.lua).
world.set{duration = 20}
world.ground{friction = 0.8}

local function walker(prefix, y, stand)
  local c = {}
  for i = 1, 4 do
    c[i] = world.spawn("superbot", {name = prefix .. "c" .. i, at = i == 1 and {0, y, 0.05} or nil})
    if i > 1 then world.connect(c[i - 1], "back", c[i], "front") end
  end
  local function leg(body, side, phase, name)
    local m = world.spawn("superbot", {name = prefix .. name, behavior = "tests/behaviors/walker_leg.lua",
                                       params = {side = side, phase = phase, stand = stand}})
    world.connect(body, side, m, "front")
  end
  -- Diagonal pairs together: the front left and the rear right, then the front right and the rear left.
  leg(c[2], "left", 0, "lf")
  leg(c[2], "right", 0.5, "rf")
  leg(c[4], "left", 0.5, "lr")
  leg(c[4], "right", 0, "rr")
  world.place_on_ground(c[1])
  return c[1]
end
local walking = walker("w", 0, false)
local standing = walker("s", 1.5, true)

local w0, s3
world.on_step(function(t)
  w0 = w0 or walking:position()
  if t >= 3 and not s3 then s3 = standing:position() end
end)

world.on_end(function()
  local w1, s1 = walking:position(), standing:position()
  local forward, aside = w1.x - w0.x, w1.y - w0.y
  expect(forward > 0.15 and forward < 0.32,
         string.format("the walker's head moved %.3f m forward in 20 s, expected 0.15 to 0.32 (0.20 to 0.23 " ..
                       "by two other solves; swept, 0.47)", forward))
  expect(math.abs(aside) < 0.08, string.format("the walker's head moved %.3f m aside, expected under 0.08", aside))
  local drift = math.sqrt((s1.x - s3.x) ^ 2 + (s1.y - s3.y) ^ 2 + (s1.z - s3.z) ^ 2)
  expect(drift < 0.0005,
         string.format("the standing walker moved %.4f mm from 3 s to 20 s, expected under 0.5 (as at rest)", drift * 1000))
  expect(s1.z > 0.100 and s1.z < 0.120,
         string.format("the standing walker's head is %.4f m up, expected 0.100 to 0.120 (0.110)", s1.z))
  world.metric("walked_m", forward)
  world.metric("aside_m", aside)
  world.metric("standing_mm", drift * 1000)
  world.metric("standing_height_m", s1.z)
end)
