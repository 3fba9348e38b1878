world.set{duration = 0.3}
world.every(0.05, function() error(setmetatable({}, {__tostring = function() error('again') end})) end) --!
