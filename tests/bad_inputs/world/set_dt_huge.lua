world.set({dt = 1e300}) --!
