world.set{duration = 0.2}
world.heightfield{image = "heightfield_huge.png", size = {1, 1}, height = 0.1} --!
