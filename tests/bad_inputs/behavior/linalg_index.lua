local linalg = require("linalg")
function step(dt)
  return linalg.vector{1, 2, 3}:get(4) --!
end
