world.set{duration = 0.2}
world.capsule{radius = 0, length = 0.1} --!
