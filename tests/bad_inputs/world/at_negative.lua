world.set{duration = 0.2}
world.at(-1, function() end) --!
