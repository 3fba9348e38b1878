-- Drives a Wheelbot straight ahead at params.speed (rad/s on every wheel; default 6) from
-- params.start (s; default 0) on, and stops once its front dock is engaged.
local wheels = {}
for _, name in ipairs(module.joints()) do wheels[#wheels + 1] = module.joint(name) end
local front = module.dock("front")
function step(dt)
  local v = (front:engaged() or sim.time() < (params.start or 0)) and 0 or (params.speed or 6)
  for _, w in ipairs(wheels) do w:set_velocity(v) end
end
