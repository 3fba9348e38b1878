world.set{duration = 0.1}
world.trace("x", "1")
