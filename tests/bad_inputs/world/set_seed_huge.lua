world.set({seed = 1e300}) --!
