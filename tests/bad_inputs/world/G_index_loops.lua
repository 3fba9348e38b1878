world.set{duration = 0.2}
setmetatable(_G, {__index = function() while true do end end})
