world.set{duration = 0.2}
world.spawn('superbot', {at = {1e300, 0, 0}}) --!
