world.set{duration = 0.2}
world.every(-1, function() end) --!
