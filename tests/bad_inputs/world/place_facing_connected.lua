world.set{duration = 0.2}
local a, b = world.spawn("superbot"), world.spawn("superbot")
world.connect(a, "back", b, "front")
world.place_facing(a, "left", b, "right")
