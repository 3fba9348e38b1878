world.set{duration = 0.2}
error(setmetatable({}, {__tostring = function() return {} end})) --!
