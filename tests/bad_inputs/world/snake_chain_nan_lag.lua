world.set{duration = 0.2}
world.ground{}
require("snake_chain").build{n = 6, lag = 0 / 0, behavior = "behaviors/snake.lua"}
