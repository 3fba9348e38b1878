-- Allocates without bound (for runaway_scripts.lua).
local t = {}
function step(dt)
  for i = 1, 1e6 do t[#t + 1] = string.rep("x", 100) .. i end
end
