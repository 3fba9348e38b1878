local linalg = require("linalg")
function step(dt)
  local A = linalg.identity(2000) --!
  return (A * A):det()
end
