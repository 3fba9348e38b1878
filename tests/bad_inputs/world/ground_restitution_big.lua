world.set{duration = 0.2}
world.ground{restitution = 1.5} --!
