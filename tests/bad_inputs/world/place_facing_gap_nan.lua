world.set{duration = 0.2}
local a, b = world.spawn("superbot"), world.spawn("superbot")
world.place_facing(a, "back", b, "front", 0/0)
