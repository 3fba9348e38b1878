world.set{duration = 0.2}
error(nil) --!
