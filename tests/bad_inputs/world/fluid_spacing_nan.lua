-- world.fluid with a NaN spacing
world.fluid{min = {0, 0, 0}, max = {0.1, 0.1, 0.1}, spacing = 0 / 0}
