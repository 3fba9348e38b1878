-- Asks for a joint SuperBots do not have (for bad_names.lua).
local elbow = module.joint("elbow")
function step(dt) end
