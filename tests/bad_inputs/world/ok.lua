-- A valid, tiny world: the command-line cases use it.
world.set{duration = 0.2}
world.ground{}
world.spawn("superbot", {at = {0, 0, 0.043}, behavior = "behaviors/hold.lua"})
