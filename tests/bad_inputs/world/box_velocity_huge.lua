world.set{duration = 0.2}
world.box{size = {1, 1, 1}, mass = 1, velocity = {1e300, 0, 0}} --!
