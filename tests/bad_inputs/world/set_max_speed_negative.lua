world.set({max_speed = -1}) --!
