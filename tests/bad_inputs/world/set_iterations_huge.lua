world.set({solver_iterations = 1e12}) --!
