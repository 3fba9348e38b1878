world.set{duration = 0.2}
world.box{size = {1, 1, 1}, mass = 0/0} --!
