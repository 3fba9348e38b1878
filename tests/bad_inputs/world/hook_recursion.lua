world.set{duration = 0.3}
local function f() return 1 + f() end
world.at(0.1, function() f() end)
--!
