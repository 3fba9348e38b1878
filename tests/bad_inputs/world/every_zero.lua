world.set{duration = 0.2}
world.every(0, function() end) --!
