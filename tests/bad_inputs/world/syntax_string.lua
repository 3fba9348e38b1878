world.set{duration = 0.2}
local s = "abc --!
print(s)
