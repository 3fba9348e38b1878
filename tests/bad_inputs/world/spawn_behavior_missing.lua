world.set{duration = 0.2}
world.spawn('superbot', {behavior = 'no_such_behaviour.lua'}) --!
