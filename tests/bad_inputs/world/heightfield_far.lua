world.set{duration = 0.2}
world.heightfield{image = "heightfield_1px.png", size = {1, 1}, height = 0.1, at = {1e9, 0, 0}} --!
