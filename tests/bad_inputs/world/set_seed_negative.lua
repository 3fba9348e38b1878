world.set({seed = -1}) --!
