-- A Wheelbot drives through a field of debris (granular particles with friction, world.debris)
-- while a second one drives beside it on bare ground: the grains are pushed aside and piled up
-- ahead of the chassis, they push back on the robot (two-way coupling), and it comes out of the
-- field slower than its twin. The field is 1.2 x 0.5 m of 1 cm grains, 2 cm deep (12,000 grains;
-- --param spacing=0.02 for fewer, --param depth= for more). The robot rides 1.5 cm above the
-- ground on 4 cm wheels: a deeper field (--param depth=0.04) beaches it on the grains it ploughs up.
--
--   ./build/rm3d run worlds/debris.lua --seconds 8 [--threads 2] [--json out.json]
--
-- The checks (after 8 s): both robots moved forward, the one in the debris at least 0.3 m and
-- less far than its twin; no grain was lost or went NaN.
world.set{duration = 8}
world.ground{friction = 1.0}

local spacing = tonumber(args.spacing or 0.01)
local depth = tonumber(args.depth or 0.02)
local field = world.debris{min = {0.0, -0.25, 0}, max = {1.2, 0.25, depth}, spacing = spacing, friction = 0.6,
                           density = 1600}
local n = field:count()

local wading = world.spawn("wheelbot", {name = "wading", at = {-0.25, 0, 0.041}, behavior = "behaviors/drive.lua"})
local twin = world.spawn("wheelbot", {name = "twin", at = {-0.25, 0.6, 0.041}, behavior = "behaviors/drive.lua"})
local start = {wading = wading:position().x, twin = twin:position().x}
world.camera{eye = {0.6, -1.6, 1.0}, target = {0.6, 0.2, 0}}

world.every(1, function(t)
  local lo, hi = field:bounds()
  print(string.format("t=%.0f s  wading x=%+.2f  twin x=%+.2f  debris top z=%.3f", t, wading:position().x,
                      twin:position().x, hi[3]))
end)

world.on_end(function(t)
  if t < 7.9 then return end
  local a, b = wading:position().x - start.wading, twin:position().x - start.twin
  world.metric("wading_m", a)
  world.metric("twin_m", b)
  expect(a > 0.3, string.format("the robot in the debris should get through, moved %.2f m", a))
  expect(a < b, string.format("the debris should slow the robot: %.2f m against %.2f m on bare ground", a, b))
  expect(field:count() == n, "no grain lost")
end)
