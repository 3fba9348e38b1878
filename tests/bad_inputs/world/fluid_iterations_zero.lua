-- world.fluid with zero iterations
world.fluid{min = {0, 0, 0}, max = {0.1, 0.1, 0.1}, spacing = 0.02, iterations = 0}
