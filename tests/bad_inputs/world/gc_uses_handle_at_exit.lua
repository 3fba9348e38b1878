world.set{duration = 0.2}
local m = world.spawn('superbot', {at = {0, 0, 0.1}})
g_keep = setmetatable({}, {__gc = function() print(m:position().x, world.time()) end})
