local linalg = require("linalg")
function step(dt)
  return linalg.identity(2):solve(linalg.vector{1, 0/0}) --!
end
