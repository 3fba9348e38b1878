-- A valid world that prints a lot (SIGPIPE cases).
world.set{duration = 1}
world.on_step(function(t) for i = 1, 20 do print("line", i, t) end end)
