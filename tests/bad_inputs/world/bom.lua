world.set{duration = 0.1}
