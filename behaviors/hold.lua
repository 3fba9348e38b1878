-- Holds fixed joint commands from params: targets = {joint = radians} (position servo) and
-- velocities = {joint = rad/s} (velocity drive). Useful for tests and for posing modules.
local commands = {}
for name, value in pairs(params.targets or {}) do
  local j = module.joint(name)
  commands[#commands + 1] = function() j:set_target(value) end
end
for name, value in pairs(params.velocities or {}) do
  local j = module.joint(name)
  commands[#commands + 1] = function() j:set_velocity(value) end
end

function step(dt)
  for i = 1, #commands do commands[i]() end
end
