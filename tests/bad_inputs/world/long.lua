-- A valid world that runs for a long time (SIGINT case).
world.set{duration = 100000}
world.ground{}
world.spawn("superbot", {at = {0, 0, 0.043}})
