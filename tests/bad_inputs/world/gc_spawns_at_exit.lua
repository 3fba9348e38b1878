world.set{duration = 0.2}
g_keep = setmetatable({}, {__gc = function() world.spawn('superbot') end})
