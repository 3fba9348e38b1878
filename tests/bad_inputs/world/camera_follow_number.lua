world.set{duration = 0.2}
local m = world.spawn('superbot', {at = {0, 0, 0.1}})
world.camera{follow = 5} --!
