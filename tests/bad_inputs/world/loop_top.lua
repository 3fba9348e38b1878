world.set{duration = 0.2}
while true do end --!
