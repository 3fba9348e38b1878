world.set{duration = 0.2}
world.on_step(5) --!
