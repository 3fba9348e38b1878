local t = setmetatable({}, {})
getmetatable(t).__tostring = function(s) return tostring(s) end --!
function step(dt) log(t) end
