world.set{duration = 0.2}
world.ground{}
require("snake_chain").build{n = 0, behavior = "behaviors/snake.lua"}
