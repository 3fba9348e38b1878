world.set{duration = 0.2}
error(string.rep('x', 4e6)) --!
