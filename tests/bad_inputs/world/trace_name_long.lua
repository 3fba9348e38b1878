world.set{duration = 0.1}
world.trace(string.rep("x", 65), 1)
