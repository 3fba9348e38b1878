world.set{duration = 0.2}
local a = world.spawn('superbot', {at = {0, 0, 0.1}})
local b = world.spawn('superbot', {at = {1, 0, 0.1}})
world.connect(a, 'front', b, 'back', 'x') --!
