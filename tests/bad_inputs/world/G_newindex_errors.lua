world.set{duration = 0.2}
world.on_step(function() end)
setmetatable(_G, {__newindex = function(t, k) error('read-only ' .. tostring(k)) end, __index = function() error('nope') end})
