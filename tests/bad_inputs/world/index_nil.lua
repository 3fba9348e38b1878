world.set{duration = 0.2}
local t = nil
print(t.x) --!
