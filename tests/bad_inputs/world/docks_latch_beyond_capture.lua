world.set{duration = 0.2}
world.docks{latch_distance = 0.05}
world.spawn("superbot")
