world.set({dtt = 0.01}) --!
