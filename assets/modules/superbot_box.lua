-- SuperBot with each U-bracket simplified to one box (same links, joints, docks, masses and
-- dock faces as superbot.lua). Two collision shapes fewer per bracket: for very large swarms
-- where contact detail matters less than speed, and for comparing with bare-Bullet references.
local t = require("superbot")
t.name = "superbot_box"
t.links[1].shapes = { { box = { 0.062, 0.084, 0.084 }, at = { 0.064, 0, 0 } } }
t.links[4].shapes = { { box = { 0.062, 0.084, 0.084 }, at = { -0.064, 0, 0 } } }
t.links[1].collision, t.links[4].collision = nil, nil  -- the boxes collide themselves
return t
