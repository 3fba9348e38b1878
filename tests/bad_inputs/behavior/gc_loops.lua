g = setmetatable({}, {__gc = function() while true do end end})
function step(dt) end
