world.spawn('superbot', {at = {0, 0, 0.1}})
world.set{seed = 5} --!
