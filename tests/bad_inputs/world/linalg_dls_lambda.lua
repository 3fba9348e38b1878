local linalg = require("linalg")
local x = linalg.identity(2):dls(linalg.vector{1, 2}, "big") --!
