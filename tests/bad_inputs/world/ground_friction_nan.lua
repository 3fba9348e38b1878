world.set{duration = 0.2}
world.ground{friction = 0/0} --!
