world.set{duration = 0.1}
world.trace("a b", 2)
