world.set{duration = 0.2}
world.spawn('superbot', {params = {s = string.rep('x', 2e7)}}) --!
