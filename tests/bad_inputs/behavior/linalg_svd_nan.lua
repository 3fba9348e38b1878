local linalg = require("linalg")
function step(dt)
  local U, s, V = linalg.matrix{{0/0, 1}, {1, 1}}:svd() --!
end
