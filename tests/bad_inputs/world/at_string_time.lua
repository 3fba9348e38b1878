world.set{duration = 0.2}
world.at('soon', function() end) --!
