world.set{duration = 0.2}
local x = = 1 --!
