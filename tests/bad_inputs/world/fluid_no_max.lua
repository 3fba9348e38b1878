-- world.fluid without max
world.fluid{min = {0, 0, 0}, spacing = 0.02}
