-- world.debris with far too many particles
world.debris{min = {0, 0, 0}, max = {10, 10, 10}, spacing = 0.001}
