world.set{duration = 0.3}
world.on_step(function() error({}) end) --!
