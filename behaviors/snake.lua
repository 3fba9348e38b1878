-- Travelling-wave gait for a chain of SuperBots.
-- Each module drives one joint with a sine wave whose phase lags by `lag` per module down the
-- chain: the wave travels from tail to head and the chain crawls towards its head.
-- params:
--   index       the module's place in the chain (0 = head), given by the world
--   joint       "pitch" (vertical wave, default) or "yaw" (lateral undulation)
--   amplitude   radians (default 0.6)
--   period      seconds per wave (default 1.5)
--   lag         phase lag between neighbours, radians (default 2*pi/5)
--   ramp        seconds over which each module's wave fades in from the flat pose (default: one
--               period; 0 starts at full amplitude at once, for a chain built in the gait's pose
--               by lua/snake_chain.lua)
--   ramp_from   "tail" (default): the fade-in starts at the tail (the module whose back dock is
--               free) and is passed on towards the head through the front docks, one module every
--               1 / ramp_speed seconds; "all": every module fades in together from t = 0
--   ramp_speed  modules per second the start travels along the chain (default 10)
--
-- Why from the tail: a straight chain must get shorter as its wave grows, and on a floor with
-- Coulomb friction a whole half that slides pushes with mu m g per module whatever the speed, so
-- a chain started everywhere at once loads its middle docks with about mu W / 2 (W the chain's
-- weight). Started at the tail, the waving part crawls towards the still part and takes up its
-- own shortening; the still part does not move. The README's "Long snakes" has the figures.

local gaits = require("gaits")
local joint = module.joint(params.joint or "pitch")
local amplitude = params.amplitude or 0.6
local period = params.period or 1.5
local lag = params.lag or (2 * math.pi / 5)
local index = params.index or 0
local ramp = params.ramp or period
local rampFrom = params.ramp_from or "tail"
local rampSpeed = params.ramp_speed or 10
if rampFrom ~= "tail" and rampFrom ~= "all" then
  error("ramp_from must be \"tail\" or \"all\", got " .. tostring(rampFrom))
end
if type(rampSpeed) ~= "number" or not (rampSpeed > 0) or rampSpeed == math.huge then
  error("ramp_speed must be a positive number of modules per second, got " .. tostring(rampSpeed))
end

local kGo = "snake:start"
local function hasDock(name)
  for _, d in ipairs(module.docks()) do if d == name then return true end end
  return false
end
local front = hasDock("front") and module.dock("front") or nil
local back = hasDock("back") and module.dock("back") or nil

-- state.start: when this module's fade-in began (nil: not yet); state.passed: whether the start
-- went on to the front neighbour. Both survive a hot reload.
function init()
  if ramp <= 0 or rampFrom == "all" or not (back and back:engaged()) then state.start = 0 end
end

function step(dt)
  local t = sim.time()
  if not state.start then
    while true do  -- the start arrives from the back neighbour
      local msg = module.receive()
      if not msg then break end
      if msg.data == kGo then state.start = t end
    end
  end
  if state.start and not state.passed and front and ramp > 0 and rampFrom == "tail" and
      t - state.start + dt >= 1 / rampSpeed - dt / 2 then  -- it arrives a step later
    front:send(kGo)
    state.passed = true
  end
  local fade = 0
  if state.start then fade = ramp > 0 and math.min(1, (t - state.start) / ramp) or 1 end
  joint:set_target(gaits.wave(t, index, amplitude * fade, period, lag))
end
