local linalg = require("linalg")
function step(dt)
  local U, s, V = linalg.matrix{{math.huge, 1}, {1, 1}}:svd() --!
end
