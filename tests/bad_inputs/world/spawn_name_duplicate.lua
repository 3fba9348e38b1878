world.set{duration = 0.2}
world.spawn('superbot', {at = {0, 0, 0.1}, name = 'a'})
world.spawn('superbot', {at = {1, 0, 0.1}, name = 'a'}) --!
