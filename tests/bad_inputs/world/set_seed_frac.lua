world.set({seed = 1.5}) --!
