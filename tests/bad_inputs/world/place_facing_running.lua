world.set{duration = 0.2}
local a, b = world.spawn("superbot"), world.spawn("superbot")
world.at(0.1, function() world.place_facing(a, "back", b, "front") end)
