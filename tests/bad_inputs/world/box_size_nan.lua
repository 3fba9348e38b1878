world.set{duration = 0.2}
world.box{size = {0/0, 1, 1}} --!
