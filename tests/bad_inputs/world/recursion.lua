world.set{duration = 0.2}
local function f(n) return 1 + f(n + 1) end --!
f(1)
