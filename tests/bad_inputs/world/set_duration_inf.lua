world.set{duration = 1/0} --!
