-- A fault text with an invalid UTF-8 byte (lua_limits.lua).
function step(dt)
  error("bad byte \255 here")
end
