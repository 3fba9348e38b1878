-- Drives a Wheelbot straight ahead: every wheel at params.speed rad/s (default 6).
local wheels = {}
for _, name in ipairs(module.joints()) do wheels[#wheels + 1] = module.joint(name) end
function step(dt)
  for _, w in ipairs(wheels) do w:set_velocity(params.speed or 6) end
end
