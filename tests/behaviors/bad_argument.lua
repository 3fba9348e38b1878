-- Passes a string where a number is expected (for bad_names.lua).
local pitch = module.joint("pitch")
function step(dt)
  pitch:set_target("ninety")
end
