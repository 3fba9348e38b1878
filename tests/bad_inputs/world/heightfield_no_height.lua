world.set{duration = 0.2}
world.heightfield{image = "heightfield_colour.png", size = {1, 1}} --!
