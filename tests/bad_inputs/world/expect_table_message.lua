world.set{duration = 0.1}
expect(false, {1, 2}) --!
