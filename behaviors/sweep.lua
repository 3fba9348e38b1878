-- Sweeps each joint of the module in turn through a sine of `amplitude` radians, `period`
-- seconds per joint, holding the others at zero.
local amplitude = params.amplitude or 1.0
local period = params.period or 2.0
local names = module.joints()
local joints = {}
for i, n in ipairs(names) do joints[i] = module.joint(n) end

function step(dt)
  local t = sim.time()
  local active = math.floor(t / period) % #joints + 1
  for i, j in ipairs(joints) do
    j:set_target(i == active and amplitude * math.sin(2 * math.pi * (t % period) / period) or 0)
  end
end
