world.set{duration = 0.2}
local h = world.debris{min = {0, 0, 0.5}, max = {0.1, 0.1, 0.6}, spacing = 0.05}
local mt = getmetatable(h)
mt.__gc = function() while true do end end --!
