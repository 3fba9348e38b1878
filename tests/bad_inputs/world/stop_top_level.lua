world.set{duration = 5}
world.stop()
