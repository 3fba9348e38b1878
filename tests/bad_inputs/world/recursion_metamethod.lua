world.set{duration = 0.2}
local t = setmetatable({}, {})
getmetatable(t).__index = function(s, k) return s[k] end --!
print(t.x)
