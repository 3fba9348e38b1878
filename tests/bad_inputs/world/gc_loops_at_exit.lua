world.set{duration = 0.2}
setmetatable({}, {__gc = function() while true do end end})
g_keep = setmetatable({}, {__gc = function() while true do end end})
