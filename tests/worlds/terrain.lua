-- Heightfield terrain: SuperBots resting on the three terraces of tests/worlds/terrain_steps.png
-- (gray 0, 128 and 255; made by assets/terrain/make_terrain.lua) sit at the height the image says
-- (within 2 mm of a twin on the flat ground, lifted by the terrace's height); hf:height_at reads
-- the image back; a Wheelbot's range sensor, looking up the ramp from the low terrace, reads the
-- distance to the terrain's surface (within 2 mm of the ray marched against hf:height_at); a
-- ball dropped on the high terrace lands on it and falls asleep.
world.set{duration = 3}
world.ground{friction = 0.8}

local kBase, kHeight = 0.05, 0.2
-- 30 x 30 pixels over 2.9 m: 0.1 m cells; columns 0-7 gray 0, 12-17 gray 128, 22-29 gray 255.
local hf = world.heightfield{image = "terrain_steps.png", size = {2.9, 2.9}, height = kHeight,
                             at = {0, 0, kBase}, friction = 0.8}
local function xOf(column) return -1.45 + 0.1 * column end
local terraces = {
  {x = xOf(3.5), z = kBase},
  {x = xOf(14.5), z = kBase + kHeight * 128 / 255},
  {x = xOf(25.5), z = kBase + kHeight},
}

local kRest = 0.043  -- a SuperBot's height lying flat, roughly (the twin gives it exactly)
local twin = world.spawn("superbot", {name = "twin", at = {0, 3, kRest}})
for i, t in ipairs(terraces) do
  t.m = world.spawn("superbot", {name = "terrace_" .. i, at = {t.x, -0.6, t.z + kRest + 0.002}})
end

-- The Wheelbot on the low terrace, looking along +x at the ramp that starts at column 7.
local bot = world.spawn("wheelbot", {name = "ranger", at = {xOf(3), 0.6, kBase + 0.041}})
local ball = world.sphere{radius = 0.05, mass = 0.2, at = {xOf(25), 0.8, kBase + kHeight + 0.3}}

-- The static facts first: heights read back from the image.
expect(hf:count() == 900, "the 30 x 30 image gives 900 samples, got " .. hf:count())
local nx, ny = hf:resolution()
expect(nx == 30 and ny == 30, string.format("resolution 30 x 30, got %d x %d", nx, ny))
for _, t in ipairs(terraces) do
  local h = hf:height_at(t.x, 0.3)
  expect(math.abs(h - t.z) < 1e-6, string.format("height_at(%.2f) = %.6f, the image says %.6f", t.x, h, t.z))
end
expect(hf:height_at(3, 0) == nil, "height_at off the terrain is nil")
local c, q = hf:position(), hf:orientation()
expect(math.abs(c.z - kBase) < 1e-6 and math.abs(c.x) < 1e-6 and math.abs(q[1] - 1) < 1e-6, "position and orientation")
local b = hf:bounds()
expect(math.abs(b.min.x + 1.45) < 1e-6 and math.abs(b.max.z - (kBase + kHeight)) < 1e-6,
       string.format("bounds from x=%.6f to z=%.6f", b.min.x, b.max.z))

--- The distance along the ray (o, d) to the terrain, marched against hf:height_at, then bisected.
local function terrainHit(o, d, length)
  local function above(t)
    local x, y, z = o.x + d.x * t, o.y + d.y * t, o.z + d.z * t
    local h = hf:height_at(x, y)
    return h == nil or z > h
  end
  local lo, step = 0, 0.001
  while lo < length and above(lo + step) do lo = lo + step end
  if lo >= length then return nil end
  local hi = lo + step
  for _ = 1, 40 do
    local mid = (lo + hi) / 2
    if above(mid) then lo = mid else hi = mid end
  end
  return (lo + hi) / 2
end

local vec = require("vec")
world.at(2.5, function()
  local ref = twin:position().z
  for i, t in ipairs(terraces) do
    local z = t.m:position().z
    expect(math.abs(z - (t.z + ref)) < 0.002,
           string.format("the SuperBot on terrace %d rests at z=%.4f; the image says %.4f (terrace %.4f + %.4f)", i, z,
                         t.z + ref, t.z, ref))
  end
  -- The range sensor sits on the chassis front face (x = +0.10 in the module frame).
  local p, q = vec.v3(bot:position()), vec.q4(bot:orientation())
  local o = vec.add(p, vec.qrot(q, {0.10, 0, 0}))
  local d = vec.qrot(q, {1, 0, 0})
  local truth = terrainHit({x = o[1], y = o[2], z = o[3]}, {x = d[1], y = d[2], z = d[3]}, 2.0)
  local reading = bot:sensor("range:front")
  expect(truth ~= nil and reading ~= nil and math.abs(reading - truth) < 0.002,
         string.format("range sensor reads %s m; the terrain is %s m away", tostring(reading), tostring(truth)))
  local bz = ball:position().z
  expect(math.abs(bz - (kBase + kHeight + 0.05)) < 0.002, string.format("the ball rests on the top terrace: z=%.4f", bz))
end)
-- Asleep by the end, after 2 s still: at one substep it lands deeper (2.2 m/s, 3.7 cm a substep),
-- is still rising out of the terrace at 15 mm/s at 0.5 s, still by 1 s, and asleep at about 2.7 s.
world.on_end(function() expect(ball:sleeping(), "the ball is asleep") end)
