world.set{duration = 0.1}
for i = 1, 300 do world.trace("s" .. i, i) end
