world.set{duration = 0.2}
local t = {}
for i = 1, 1e9 do t[i] = i end --!
