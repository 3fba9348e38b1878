world.set{duration = 0.2}
world.box{size = {0.1, 0.1, 0.1}, concave = true} --!
