world.set{duration = 0.2}
world.spawn("superbot", {joints = "pitch"})
