-- A strict-mode _G whose __index raises on any unknown name (for lua_limits.lua): the host's
-- callback look-ups must not trip it; reading an undefined global in step faults with file:line.
setmetatable(_G, {__index = function() error() end})
local steps = 0
function step(dt)
  steps = steps + 1
  if sim.time() > 0.3 then local x = undefined_name end
end
