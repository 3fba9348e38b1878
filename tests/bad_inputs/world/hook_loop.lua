world.set{duration = 0.3}
world.at(0.1, function() while true do end end) --!
