world.set{duration = 0.2}
print(string.format('%d', 1.5)) --!
