-- Travelling-wave gait for a chain of SuperBots.
-- Each module drives one joint with a sine wave whose phase lags by `lag` per module down the
-- chain: the wave travels from tail to head and the chain crawls towards its head.
-- params:
--   index      the module's place in the chain (0 = head), given by the world
--   joint      "pitch" (vertical wave, default) or "yaw" (lateral undulation)
--   amplitude  radians (default 0.6)
--   period     seconds per wave (default 1.5)
--   lag        phase lag between neighbours, radians (default 2*pi/5)
--   ramp       seconds over which the wave fades in from the flat pose (default: one period;
--              0 starts at full amplitude, which jerks a long chain from rest)

local gaits = require("gaits")
local joint = module.joint(params.joint or "pitch")
local amplitude = params.amplitude or 0.6
local period = params.period or 1.5
local lag = params.lag or (2 * math.pi / 5)
local index = params.index or 0
local ramp = params.ramp or period

function step(dt)
  local t = sim.time()
  local fade = ramp > 0 and math.min(1, t / ramp) or 1
  joint:set_target(gaits.wave(t, index, amplitude * fade, period, lag))
end
