local linalg = require("linalg")
local a = linalg.zeros(4096, 4096)
local b = linalg.zeros(4096, 4096) --!
