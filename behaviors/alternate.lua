-- Every joint alternates between two targets (the paper's scalability test, section IV.G).
-- params: amplitude (radians, default 0.5), period (seconds for a full back-and-forth, default 2)

local gaits = require("gaits")
local amplitude = params.amplitude or 0.5
local period = params.period or 2.0
local joints = {}
for i, name in ipairs(module.joints()) do joints[i] = module.joint(name) end

function step(dt)
  local target = gaits.square(sim.time(), amplitude, period)
  for i = 1, #joints do joints[i]:set_target(target) end
end
