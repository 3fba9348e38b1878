world.set{duration = 0.2}
world.heightfield{image = "evil_link.png", size = {1, 1}, height = 0.1} --!
