world.set{duration = 0.3}
local function add() world.on_step(add); world.on_step(add) end
world.on_step(add)
