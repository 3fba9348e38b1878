world.set{duration = 0.2}
world.spawn('superbot', {at = {0, 0, 0.1}})
getmetatable('').__index = function() error('strings broken') end
getmetatable('').__concat = function() error('concat broken') end
