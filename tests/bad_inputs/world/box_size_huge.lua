world.set{duration = 0.2}
world.box{size = {1e300, 1, 1}} --!
