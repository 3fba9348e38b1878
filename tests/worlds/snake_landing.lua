-- A 10-module snake put down in its gait's pose (lua/snake_chain.lua) at the world's defaults:
-- its raised head lands at about 0.12 s. When a motor saturates, the exact solver sweeps the
-- contacts again with that hinge no longer holding its links; without that sweep the landing
-- impulse, found for the held structure, fell on the head link alone and its pitch joint turned
-- 49.5 deg in one step (with it 3.4 deg; at 20 substeps x 100 iterations 2.7 deg). The servo's
-- own speed limit is 3 rad/s, 2.9 deg a step.
world.set{duration = 0.5}
world.ground{}
local chain = require("snake_chain").build{n = 10, behavior = "behaviors/snake.lua"}
local head = chain[1]
local last, worst, at = head:joint_angle("pitch"), 0, 0
world.on_step(function(t)
  local a = head:joint_angle("pitch")
  if math.abs(a - last) > worst then worst, at = math.abs(a - last), t end
  last = a
end)
world.at(0.5, function()
  log(string.format("largest head pitch change in one step: %.2f deg at %.3f s", math.deg(worst), at))
  expect(math.deg(worst) < 10, string.format("the head's pitch turned %.1f deg in one step at %.3f s", math.deg(worst), at))
end)
