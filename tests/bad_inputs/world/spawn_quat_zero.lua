world.set{duration = 0.2}
world.spawn('superbot', {quat = {0, 0, 0, 0}}) --!
