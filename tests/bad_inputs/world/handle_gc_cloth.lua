world.set{duration = 0.2}
local h = world.cloth{corners = {{0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}}, resolution = {3, 3}}
local mt = getmetatable(h)
mt.__gc = function() while true do end end --!
