world.set{duration = 0.1}
world.metric("r", 1/0)
