world.set{duration = 0.2}
g_keep = setmetatable({}, {__gc = function() local t = {} for i = 1, 1e9 do t[i] = string.rep('x', 100) .. i end end})
