world.set{duration = 0.3}
world.on_step(function(t) for i = 1, 50 do world.spawn('superbot_box', {at = {i, t * 100, 0.1}}) end end)
