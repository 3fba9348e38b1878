world.set({substeps = 0}) --!
