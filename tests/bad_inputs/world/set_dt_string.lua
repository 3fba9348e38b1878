world.set({dt = "fast"}) --!
