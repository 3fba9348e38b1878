world.set{duration = 0.2}
local m = world.spawn("superbot")
world.at(0.1, function() world.place_on_ground(m) end)
