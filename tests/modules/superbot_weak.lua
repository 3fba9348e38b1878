-- A SuperBot whose docks give way at 20 N (for the breakage tests): the shipped type with only
-- the dock strengths changed.
local t = require("superbot")
t.name = "superbot_weak"
for _, d in ipairs(t.docks) do
  d.strength = 20
  d.strength_torque = 100
end
return t
