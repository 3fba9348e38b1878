world.set{duration = 0.1}
world.every(0.05, function(t) world.trace("x") end)
