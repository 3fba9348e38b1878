-- Particles first, then a cloth: both share the one budget.
world.set{duration = 0.2}
world.debris{min = {0, 0, 0.01}, max = {0.27, 0.27, 0.27}, spacing = 0.01}
world.cloth{corners = {{0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}}, resolution = {64, 64}} --!
