-- Sweeps its joints; the module with params.split_at disables its back dock at that time
-- (for split.lua).
local joints = {}
for i, n in ipairs(module.joints()) do joints[i] = module.joint(n) end
function step(dt)
  local t = sim.time()
  if params.split_at and t >= params.split_at then module.dock("back"):disable() end
  joints[1]:set_target(0.4 * math.sin(2 * math.pi * t))
end
