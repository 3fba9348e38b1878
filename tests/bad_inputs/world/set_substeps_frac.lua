world.set({substeps = 2.5}) --!
