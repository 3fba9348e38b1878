-- An endless finalizer: refused by setmetatable (lua_limits.lua).
function step(dt)
  setmetatable({}, {__gc = function() while true do end end})
end
