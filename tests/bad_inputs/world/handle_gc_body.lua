world.set{duration = 0.2}
local h = world.box{size = {0.1, 0.1, 0.1}, at = {0, 0, 1}, mass = 1}
local mt = getmetatable(h)
mt.__gc = function() while true do end end --!
