world.set({dt = 0/0}) --!
