world.set({duration = -1}) --!
