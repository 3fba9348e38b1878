local linalg = require("linalg")
function step(dt)
  local m = linalg.zeros(4096, 4096) --!
end
