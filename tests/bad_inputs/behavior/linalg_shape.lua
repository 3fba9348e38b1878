local linalg = require("linalg")
function step(dt)
  local x = linalg.zeros(6, 9) * linalg.vector{1, 2, 3} --!
end
