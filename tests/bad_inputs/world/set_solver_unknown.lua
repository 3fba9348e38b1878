world.set({solver = "magic"}) --!
