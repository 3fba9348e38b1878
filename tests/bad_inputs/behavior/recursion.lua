local function f() return 1 + f() end
function step(dt) f() end --!
