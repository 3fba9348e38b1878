-- ATRON whose hemispheres collide as their drawn 193-point meshes, as every ATRON did before its
-- 65-point collision hull. Same masses, inertias, joint and docks as atron.lua: for comparing
-- the two (tests).
local t = require("atron")
t.name = "atron_fine"
t.links[1].collision, t.links[2].collision = nil, nil
return t
