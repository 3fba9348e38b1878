world.set{duration = 0.3}
world.at(0.1, function() local x = nil; return x.y end) --!
