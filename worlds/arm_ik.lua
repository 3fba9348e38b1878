-- A 9-DOF modular arm reaching targets by damped least squares (the paper's Fig. 1(d), IV.C):
-- three SuperBots joined by two elongated docks stand on a fixed elongated dock (the base, its
-- foot at the origin, so the base frame is the world frame: z up). behaviors/arm_ik.lua runs the
-- IK in the middle SuperBot, closed on the measured joint angles that the modules pass along
-- their docks, in the physics, under gravity, within the servos' torque and speed limits, on the
-- exact joint solver. lua/arm_ik_world.lua builds it and says how targets are drawn (reachable
-- and statically feasible, from the world's seed).
--
--   rm3d run worlds/arm_ik.lua --param targets=50 [--seed N] [--param slot=5]
--   rm3d run worlds/arm_ik.lua --param target=0.1,0.05,0.7
--
-- Each target holds for `slot` seconds (default 5). Reported as metrics in the JSON summary and
-- printed at the end: ik_error_mm_max and ik_error_mm_mean (the tip's distance to each target at
-- the end of its slot), settle_time_s and settle_time_s_max (when it came within 1 mm for good),
-- reached_1mm, and the peak joint torque and dock loads.
local arm = require("arm_ik_world")

world.ground{}
local opts = { slot = tonumber(args.slot) }
if args.slot ~= nil and not (opts.slot and opts.slot >= 0.1 and opts.slot <= 600) then
  error("--param slot=S: expected seconds per target, 0.1 .. 600, got " .. tostring(args.slot))
end
if args.target then
  local x, y, z = tostring(args.target):match("^%s*([^,]+),([^,]+),([^,]+)%s*$")
  x, y, z = tonumber(x), tonumber(y), tonumber(z)
  if not (x and y and z) then
    error("--param target=x,y,z: expected three numbers (metres, base frame), got '" .. tostring(args.target) .. "'")
  end
  opts.target = { x, y, z }
else
  opts.targets = math.tointeger(tonumber(args.targets or 10))
  if not opts.targets or opts.targets < 1 or opts.targets > 10000 then
    error("--param targets=N: expected a whole number 1 .. 10000, got " .. tostring(args.targets))
  end
end
world.camera{ eye = { 0.75, -1.15, 0.7 }, target = { 0, 0, 0.45 }, fov = 45 }
local a = arm.build(opts)
world.on_end(function() arm.report(a) end)
