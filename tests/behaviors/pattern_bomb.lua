-- A backtracking pattern that the stock matcher would run for years (lua_limits.lua).
local s = string.rep("a", 5000)
function step(dt)
  return s:find(".-.-.-.-.-.-b")
end
