world.set{duration = 0.2}
world.spawn('superbot', {at = {0, 0, 0.1}, params = {f = print}}) --!
