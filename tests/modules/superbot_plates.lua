-- SuperBot whose brackets collide with their three plates (the visual shapes), as every
-- SuperBot did before module types had separate collision geometry. Same masses, inertias,
-- joints and docks as superbot.lua: for comparing the two (tests, `rm3d bench --type`).
local t = require("superbot")
t.name = "superbot_plates"
t.links[1].collision, t.links[4].collision = nil, nil
return t
