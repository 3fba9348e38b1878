world.set{duration = 0.2}
world.cloth() --!
