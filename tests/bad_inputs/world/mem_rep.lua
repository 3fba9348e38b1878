world.set{duration = 0.2}
local s = string.rep('x', 1e10) --!
