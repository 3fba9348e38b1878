world.set{duration = 5}
world.at(0.1, function() world.stop(5, 'x') end)
