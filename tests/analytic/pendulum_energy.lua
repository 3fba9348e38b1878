-- Analytic check: a free hinge pendulum let go with its arm horizontal (90 deg) keeps swinging to
-- 90 deg (no friction anywhere: its energy is conserved), with the large-amplitude period
-- 4 sqrt(I / (m g d)) K(sin 45 deg), K the complete elliptic integral of the first kind.
-- The pendulum is modules/pendulum.lua (as pendulum_period.lua), its base fixed in space and turned
-- 90 deg about y. Measured at the defaults (one substep): 88.8-89.0 deg after 10 s (the loss is of
-- order (h w)^4 a substep: 89.9 at two substeps), period within 0.1%; before the
-- exact solver's hinge rows took their centripetal target it swung 54.6 deg after 10 s (a share
-- (h w)^2 of the swing's energy went at every substep). `--param solver=pgs` runs it on the old solver.
local type_ = require("modules.pendulum")
if args.solver then world.set{solver = args.solver} end
local duration = 10.0
world.set{duration = duration}

local arm
for _, l in ipairs(type_.links) do if l.name == "arm" then arm = l end end
local m, box, at, pivot = arm.mass, arm.shapes[1].box, arm.shapes[1].at, type_.joints[1].pivot
local g = 9.81
local dx, dz = at[1] - pivot[1], at[3] - pivot[3]
local d = math.sqrt(dx * dx + dz * dz)
local inertia = m * (box[1] ^ 2 + box[3] ^ 2) / 12 + m * d * d -- about y through the pivot
local theta0 = math.rad(90)
-- K(k) = pi / (2 AGM(1, sqrt(1 - k^2))).
local a, b = 1.0, math.sqrt(1 - math.sin(theta0 / 2) ^ 2)
for _ = 1, 20 do a, b = (a + b) / 2, math.sqrt(a * b) end
local expected = 4 * math.sqrt(inertia / (m * g * d)) * math.pi / (2 * a)

local p = world.spawn("modules/pendulum.lua", {at = {0, 0, 1}, rot = {0, theta0, 0}, fixed = true,
                                               behavior = "../behaviors/free_joints.lua", params = {free = {"swing"}}})
-- The swing about hanging straight down (joint angle -90 deg).
local crossings, prevT, prevA = {}, 0, 0
local lastLo, lastHi = 0, 0
world.on_step(function(t)
  local s = p:joint_angle("swing") + theta0
  if t > duration - 2 * expected then lastLo, lastHi = math.min(lastLo, s), math.max(lastHi, s) end
  if prevA < 0 and s >= 0 then crossings[#crossings + 1] = prevT + (t - prevT) * (-prevA) / (s - prevA) end
  prevT, prevA = t, s
end)

world.on_end(function()
  local lo, hi = math.deg(lastLo), math.deg(lastHi)
  log(string.format("swing over the last two periods %+.2f..%+.2f deg (let go at 90 deg)", lo, hi))
  expect(hi > 88.5 and lo < -88.5, string.format("swing %+.2f..%+.2f deg after %.0f s, expected within 1.5 deg of +-90",
                                             lo, hi, duration))
  expect(#crossings >= 4, string.format("%d upward zero crossings, expected at least 4", #crossings))
  if #crossings < 2 then return end
  local period = (crossings[#crossings] - crossings[1]) / (#crossings - 1)
  local err = (period - expected) / expected
  log(string.format("period %.5f s over %d periods, expected %.5f s: %+.3f%%", period, #crossings - 1, expected,
                    100 * err))
  expect(math.abs(err) < 0.01, string.format("period %.5f s, expected %.5f s within 1%% (off by %+.3f%%)",
                                             period, expected, 100 * err))
end)
