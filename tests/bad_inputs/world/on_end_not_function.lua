world.set{duration = 0.1}
world.on_end(42)
