world.set{duration = 0.2}
world.sphere{radius = 0.05, mass = 1, rolling_friction = -1} --!
