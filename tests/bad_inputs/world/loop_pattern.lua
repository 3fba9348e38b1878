world.set{duration = 0.2}
local s = string.rep('a', 50000)
print(s:find('.-.-.-.-.-.-.-b')) --!
