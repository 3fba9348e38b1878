world.set{duration = 0.1}
expect(false, setmetatable({}, {__tostring = function() error('x') end})) --!
