-- world.fluid with a misspelled key
world.fluid{min = {0, 0, 0}, max = {0.1, 0.1, 0.1}, spaceing = 0.02}
