world.set{duration = 0.2}
local h = world.spawn("superbot", {at = {0, 0, 0.043}})
local mt = getmetatable(h)
mt.__gc = function() while true do end end --!
