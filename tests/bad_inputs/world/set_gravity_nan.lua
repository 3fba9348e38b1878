world.set({gravity = {0, 0, 0/0}}) --!
