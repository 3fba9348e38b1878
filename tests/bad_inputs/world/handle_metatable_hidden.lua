world.set{duration = 0.2}
local h = world.box{size = {0.1, 0.1, 0.1}, at = {0, 0, 1}, mass = 1}
assert(getmetatable(h) == false and getmetatable(world.spawn("superbot", {at = {1, 0, 0.043}})) == false)
print("SEALED-OK")
