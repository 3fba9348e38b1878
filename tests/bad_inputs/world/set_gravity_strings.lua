world.set({gravity = {"a", "b", "c"}}) --!
