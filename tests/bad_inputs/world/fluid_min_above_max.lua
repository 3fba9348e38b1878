-- world.fluid with min above max
world.fluid{min = {0, 0, 0.2}, max = {0.1, 0.1, 0.1}, spacing = 0.02}
