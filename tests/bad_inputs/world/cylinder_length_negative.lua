world.set{duration = 0.2}
world.cylinder{radius = 1, length = -2} --!
