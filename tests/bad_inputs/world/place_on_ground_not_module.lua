world.set{duration = 0.2}
world.place_on_ground({})
