world.set{duration = 0.2}
local m = world.spawn("superbot")
world.place_on_ground(m, 1e300)
