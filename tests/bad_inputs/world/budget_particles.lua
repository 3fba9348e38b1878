-- More particles than a small --memory-budget holds: refused before any is made.
world.set{duration = 0.2}
world.debris{min = {0, 0, 0.01}, max = {0.4, 0.4, 0.4}, spacing = 0.01} --!
