world.set{duration = 5}
world.on_step(function() world.stop(); world.stop() end)
