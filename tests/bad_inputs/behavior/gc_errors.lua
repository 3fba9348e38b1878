g = setmetatable({}, {__gc = function() error('gc failed') end})
function step(dt) end
