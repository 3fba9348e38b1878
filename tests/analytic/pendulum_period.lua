-- Analytic check: a free hinge pendulum's small-angle period is 2*pi*sqrt(I / (m g d)) within 1%.
-- The pendulum (modules/pendulum.lua) is a box arm on a free hinge whose base is fixed in space,
-- tilted 5 degrees so the arm starts 5 degrees from hanging straight down, at rest. I (about the
-- pivot), m and d (pivot to centre of mass) come from the module-type table itself; the finite
-- amplitude lengthens the period by (1 + theta0^2 / 16), 0.05% at 5 degrees, included.
-- The period is measured from upward zero crossings (linearly interpolated) of the swing angle
-- about its equilibrium over 8 periods (10 s). `--param solver=pgs` runs it on the old solver.
local type_ = require("modules.pendulum")
if args.solver then world.set{solver = args.solver} end
world.set{duration = 10.0}

local arm, swing
for _, l in ipairs(type_.links) do if l.name == "arm" then arm = l end end
swing = type_.joints[1]
local m, box, at, pivot = arm.mass, arm.shapes[1].box, arm.shapes[1].at, swing.pivot
local g = 9.81
local dx, dz = at[1] - pivot[1], at[3] - pivot[3]
local d = math.sqrt(dx * dx + dz * dz)
local inertia = m * (box[1] ^ 2 + box[3] ^ 2) / 12 + m * d * d -- about y through the pivot
local theta0 = math.rad(5)
local expected = 2 * math.pi * math.sqrt(inertia / (m * g * d)) * (1 + theta0 ^ 2 / 16)

-- Base turned +5 deg about y: at joint angle 0 the arm hangs 5 deg off the vertical, and the
-- equilibrium (arm straight down) is at joint angle -5 deg.
local p = world.spawn("modules/pendulum.lua", {at = {0, 0, 1}, rot = {0, theta0, 0}, fixed = true,
                                               behavior = "../behaviors/free_joints.lua", params = {free = {"swing"}}})
local centre = -theta0
local crossings, prevT, prevA = {}, 0, 0
local lo, hi = math.huge, -math.huge
world.on_step(function(t)
  local a = p:joint_angle("swing") - centre
  lo, hi = math.min(lo, a), math.max(hi, a)
  if prevA < 0 and a >= 0 then crossings[#crossings + 1] = prevT + (t - prevT) * (-prevA) / (a - prevA) end
  prevT, prevA = t, a
end)

world.on_end(function()
  expect(#crossings >= 8, string.format("%d upward zero crossings in 10 s, expected at least 8", #crossings))
  if #crossings < 2 then return end
  local period = (crossings[#crossings] - crossings[1]) / (#crossings - 1)
  local err = (period - expected) / expected
  log(string.format("period %.5f s over %d periods, expected %.5f s (I=%.6f kg m^2, m=%.3f kg, d=%.3f m): %+.3f%%;"
                      .. " swing %+.2f..%+.2f deg about equilibrium",
                    period, #crossings - 1, expected, inertia, m, d, 100 * err, math.deg(lo), math.deg(hi)))
  expect(math.abs(err) < 0.01, string.format("period %.5f s, expected %.5f s within 1%% (off by %+.3f%%)",
                                             period, expected, 100 * err))
end)
