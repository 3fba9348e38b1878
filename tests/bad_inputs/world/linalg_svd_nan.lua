local linalg = require("linalg")
local A = linalg.matrix{{0/0, 1}, {1, 1}}
local U, s, V = A:svd() --!
