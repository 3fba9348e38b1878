world.set({substeps = 1e12}) --!
