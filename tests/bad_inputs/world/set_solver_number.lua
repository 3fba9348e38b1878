world.set{solver = 3} --!
