world.set{duration = 0.2}
local evil = require("evil_link") --!
