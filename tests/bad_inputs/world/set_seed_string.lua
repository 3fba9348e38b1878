world.set({seed = "abc"}) --!
