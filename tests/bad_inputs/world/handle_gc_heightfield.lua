world.set{duration = 0.2}
local h = world.heightfield{image = "assets/terrain/hills_30.png", size = {1, 1}, height = 0.1}
local mt = getmetatable(h)
mt.__gc = function() while true do end end --!
