world.set{duration = 0.2}
world.fluid{min = {0, 0, 0.5}, max = {0.1, 0.1, 0.6}, iterations = 2, substeps = 10} --!
