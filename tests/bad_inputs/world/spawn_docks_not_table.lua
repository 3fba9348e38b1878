world.set{duration = 0.2}
world.spawn("superbot", {docks = 3})
