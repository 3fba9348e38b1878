world.set{duration = 0.2}
world.cloth{corners = {{0, 0, 1}, {1, 0, 1}, {2, 0, 1}, {3, 0, 1}}} --!
