-- The 9-DOF arm of worlds/arm_ik.lua (built by lua/arm_ik_world.lua, behaviors/arm_ik.lua):
-- four random reachable targets from the seed, under gravity on the exact solver; the tip must
-- end each 5 s slot within 1 mm of its target, and no dock may break.
local arm = require("arm_ik_world")
world.ground{}
local a = arm.build{targets = 4, slot = 5}
world.on_end(function()
  local s = arm.report(a)
  expect(s.n == 4, "all four targets measured, got " .. s.n)
  for k = 1, s.n do
    expect(a.errors[k] < 0.001, string.format("target %d: the tip ended %.3f mm away, expected < 1 mm", k, a.errors[k] * 1000))
  end
  local broken = 0
  for _, e in ipairs(world.events()) do
    if e.event == "broken" then broken = broken + 1 end
  end
  expect(broken == 0, broken .. " dock connections broke")
end)
