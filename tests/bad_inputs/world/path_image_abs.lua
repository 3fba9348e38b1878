world.set{duration = 0.2}
world.heightfield{image = "/etc/hostname", size = {1, 1}, height = 0.1} --!
