local linalg = require("linalg")
local x = linalg.identity(2) + linalg.identity(3) --!
