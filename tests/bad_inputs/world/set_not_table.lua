world.set(5) --!
