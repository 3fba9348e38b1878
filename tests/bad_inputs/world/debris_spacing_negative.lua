-- world.debris with a negative spacing
world.debris{min = {0, 0, 0}, max = {0.1, 0.1, 0.1}, spacing = -0.01}
