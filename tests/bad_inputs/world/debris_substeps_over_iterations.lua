world.set{duration = 0.2}
world.debris{min = {0, 0, 0.5}, max = {0.1, 0.1, 0.6}, iterations = 1, substeps = 3} --!
