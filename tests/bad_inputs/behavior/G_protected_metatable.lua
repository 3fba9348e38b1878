function step(dt) end
setmetatable(_G, {__metatable = 'locked', __index = function(t, k) return nil end})
