world.set{duration = 0.2}
print(table.unpack({}, 1, 1e8)) --!
