world.set{duration = 0.2}
world.heightfield{image = "ok.lua", size = {1, 1}, height = 0.1} --!
