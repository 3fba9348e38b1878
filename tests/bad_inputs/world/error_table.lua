world.set{duration = 0.2}
error({code = 1}) --!
