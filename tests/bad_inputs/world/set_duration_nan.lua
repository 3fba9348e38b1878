world.set({duration = 0/0}) --!
