world.set{duration = 0.2}
world.heightfield{image = "no_such_terrain.png", size = {1, 1}, height = 0.1} --!
