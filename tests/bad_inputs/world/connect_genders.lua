world.set{duration = 0.2}
local a = world.spawn('atron', {at = {0, 0, 0.1}})
local b = world.spawn('atron', {at = {1, 0, 0.1}})
world.connect(a, 'n0', b, 'n0') --!
