world.set{duration = 0.2}
local s = string.rep('a', 1000)
s:gsub('a', function() while true do end end) --!
