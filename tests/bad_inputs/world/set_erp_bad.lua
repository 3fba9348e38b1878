world.set({erp = 5}) --!
