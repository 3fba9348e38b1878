world.set{duration = 0.2}
world.docks{capture_frce = 1}
