world.set{duration = 0.2}
world.sphere{radius = -1} --!
