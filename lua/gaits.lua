-- Gait helpers shared by behaviours: `local gaits = require("gaits")`.
local gaits = {}

--- Travelling sine wave: the joint angle (radians) of the module at `index` along a chain at
--- time t. The wave moves from high to low indices when lag > 0.
--- amplitude (rad), period (s), lag (rad between neighbours), offset (rad, default 0).
function gaits.wave(t, index, amplitude, period, lag, offset)
  return (offset or 0) + amplitude * math.sin(2 * math.pi * t / period + index * lag)
end

--- Square wave between -amplitude and +amplitude with the given period (s).
function gaits.square(t, amplitude, period)
  return (t % period) < period / 2 and amplitude or -amplitude
end

return gaits
