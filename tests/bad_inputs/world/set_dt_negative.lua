world.set({dt = -1}) --!
