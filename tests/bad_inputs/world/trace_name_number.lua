world.set{duration = 0.1}
world.trace(1, 2)
