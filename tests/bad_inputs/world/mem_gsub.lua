world.set{duration = 0.2}
local s = string.rep('a', 1e6):gsub('a', string.rep('b', 1000)) --!
