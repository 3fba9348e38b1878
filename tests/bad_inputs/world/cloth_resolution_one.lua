world.set{duration = 0.2}
world.cloth{corners = {{0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}}, resolution = {1, 8}} --!
