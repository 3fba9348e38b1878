-- world.fluid with a negative density
world.fluid{min = {0, 0, 0}, max = {0.1, 0.1, 0.1}, spacing = 0.02, density = -1000}
