world.set({bounds = "x"}) --!
