-- world.debris in a box thinner than one spacing
world.debris{min = {0, 0, 0}, max = {0.1, 0.1, 0.005}, spacing = 0.01}
