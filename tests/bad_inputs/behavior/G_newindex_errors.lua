function step(dt) end
setmetatable(_G, {__newindex = function(t, k) error('read-only ' .. tostring(k)) end})
