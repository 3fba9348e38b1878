world.set({gravity = 5}) --!
