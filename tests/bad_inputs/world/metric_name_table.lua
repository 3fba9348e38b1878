world.set{duration = 0.1}
world.metric({}, 1)
