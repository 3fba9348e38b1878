-- Rolling track to snake (the paper's Fig. 5, middle; worlds/track_to_snake.lua): six SuperBots
-- in a closed loop roll as the rolling track (lua/rolling_gait.lua), stop, open the loop by
-- disabling one engaged dock, lie down as a chain and crawl away as a snake. No module is told
-- its place or role; each decides from its own clock, accelerometer and docks, and messages.
--
--   roll    until `brake_at` s: the rolling track's gait at params.rate.
--   brake   the same gait told to hold rate 0: it leans back until the loop stands still as an
--           upright hexagon.
--   open    from `open_at` s, the module that finds itself on top of the loop (its angle round
--           the loop within `top_window` of 180 deg, and the loop still) disables its front dock:
--           the loop opens there, and this module becomes the snake's head (nothing at its
--           front). It sends 1 down its back dock; every other module takes the number it reads
--           on its front dock as its place in the chain and passes the next one on (the
--           caterpillar's counter, behaviors/caterpillar.lua), so the news runs down the chain
--           one hop a step. Only a module on top opens, and the hexagon's modules are 60 deg
--           apart, so one module opens.
--   lie     a module that knows its place straightens its joints (pitch 0) for `lie` s: the two
--           halves of the open loop unfold down to the ground, into a straight chain.
--   crawl   the snake's vertical travelling wave on pitch (behaviors/snake.lua's), led by the
--           head: the chain crawls towards its head.
--
-- params: the rolling track's (direction, rate, ...), and brake_at (8), open_at (10),
-- top_window (deg, 20), still (rad/s below which the loop counts as still, 0.1), lie (1.5),
-- amplitude (0.6 rad), period (1.5 s), lag (2*pi/5 rad).
local gaits = require("gaits")
local rolling_gait = require("rolling_gait")
local rolling = rolling_gait.new(params)
local wrap = rolling_gait.wrap
local pitch = module.joint("pitch")
local front, back = module.dock("front"), module.dock("back")

local brake_at = params.brake_at or 8
local open_at = params.open_at or 10
local top_window = math.rad(params.top_window or 20)
local still = params.still or 0.1
local lie = params.lie or 1.5
local amplitude = params.amplitude or 0.6
local period = params.period or 1.5
local lag = params.lag or (2 * math.pi / 5)

percepts = {where = rolling.percept}

local place      -- the module's place in the chain once the loop is open (0: the head)
local placed_at  -- when it learnt it
local angles, n = {}, 0 -- the angle round the loop, every step (the last half second kept)

local function become(index)
  place, placed_at = index, sim.time()
  back:send(index + 1) -- false at the tail: nothing is docked there
  log(string.format("chain place %d", index))
end

function step(dt)
  if place == nil then
    local msg = module.receive("front")
    if msg and type(msg.data) == "number" then become(msg.data) end
  end
  while module.receive() do end -- anything else is not for this gait

  if place == nil then
    local t = sim.time()
    rolling.step(dt, t >= brake_at and 0 or nil)
    local angle = rolling.angle()
    -- How fast the loop turns, over half a second (one step's difference is mostly noise).
    local k = math.floor(0.5 / dt + 0.5)
    n = n + 1
    angles[n], angles[n - k - 1] = angle, nil
    local spin = (angle and angles[n - k]) and math.abs(wrap(angle - angles[n - k])) / (k * dt) or math.huge
    local on_top = angle and math.abs(wrap(angle - math.pi)) < top_window
    if t >= open_at and rolling.closed() and on_top and spin < still and front:engaged() then
      front:disable()
      log("on top: opening the loop at my front dock")
      become(0)
    end
    return
  end

  local t = sim.time() - placed_at
  if t < lie then
    pitch:set_target(0)
  else
    local fade = math.min(1, (t - lie) / period)
    pitch:set_target(gaits.wave(t - lie, place, amplitude * fade, period, lag))
  end
end
