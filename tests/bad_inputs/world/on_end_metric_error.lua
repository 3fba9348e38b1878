world.set{duration = 0.1}
world.on_end(function(t) world.metric("bad name", t) end)
