world.set{duration = 0.2}
world.at(0/0, function() end) --!
