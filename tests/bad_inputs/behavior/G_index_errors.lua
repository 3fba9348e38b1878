function step(dt) end
setmetatable(_G, {__index = function(t, k) error('no global ' .. tostring(k)) end})
