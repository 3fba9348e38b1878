world.set{duration = 0.2}
g_keep = setmetatable({}, {__gc = function() error('gc failed') end})
