world.set{duration = 0.3}
local t = {}
world.on_step(function() for i = 1, 1e6 do t[#t + 1] = string.rep('y', 4096) .. i end end) --!
