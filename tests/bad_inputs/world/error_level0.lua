world.set{duration = 0.2}
error('no position', 0) --!
