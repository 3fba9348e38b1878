world.set{duration = 0.2}
local c = world.cloth{corners = {{0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}}, resolution = {3, 3}}
c:node(0) --!
