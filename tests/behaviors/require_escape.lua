-- require outside the allowed folders (lua_limits.lua).
function step(dt)
  require(".tmp.x")
end
