world.set{duration = 0.2}
world.spawn('superbot', {at = {0, 0, 0.1}})
setmetatable(_G, {__index = function(t, k) error('no global ' .. tostring(k)) end})
