-- One leg of tests/worlds/walker_trot.lua: lua/walker_gait.lua's trot without its steering (no
-- heading error), from when it starts; params.stand holds the stance after the gait's rise.
local gait = require("walker_gait")
local t0
function step(dt)
  local t = sim.time()
  t0 = t0 or t
  local pitch, yaw = gait.leg(params.stand and math.min(t - t0, gait.rise) or t - t0, params.side, params.phase, 0)
  module.joint("pitch"):set_target(pitch)
  module.joint("yaw"):set_target(yaw)
end
