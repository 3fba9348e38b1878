local linalg = require("linalg")
function step(dt)
  return linalg.matrix{{1, 2}, {3, -math.huge}}:pinv() --!
end
