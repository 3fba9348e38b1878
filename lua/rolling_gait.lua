-- The rolling track's gait as a library for behaviours (behaviors/rolling_track.lua explains the
-- gait; behaviors/track_to_snake.lua rolls with it before it reconfigures):
--
--   local rolling = require("rolling_gait").new(params)   -- the params rolling_track.lua takes
--   percepts = {where = rolling.percept}
--   function step(dt) rolling.step(dt) end                -- forms, then rolls
--
-- rolling.step(dt, rate) rolls at `rate` rad/s instead of params.rate (0 brakes to a standing
-- hexagon); rolling.angle() is the module's last angle round the loop (rad, 0 at the bottom, pi on
-- top; nil before the first reading), rolling.closed() whether its loop is docked shut.
local M = {}

local kHexagon = math.pi / 3 -- 60 deg: six equal bends close the loop
local kG = 9.81
local places = {"bottom", "front", "top", "back"}

local function wrap(a) return (a + math.pi) % (2 * math.pi) - math.pi end
M.wrap = wrap

function M.new(params)
  local pitch, roll, yaw = module.joint("pitch"), module.joint("roll"), module.joint("yaw")
  local front, back = module.dock("front"), module.dock("back")

  local direction = params.direction or 1
  local rate = params.rate or 2.5
  local max_lean = math.rad(params.max_lean or 30)
  local gain = params.gain or 1.0
  local window = params.window or 1
  local settle = params.settle or 0.5

  local self = {}
  self.percept = {
    sensor = "accelerometer",
    noise = noise.gaussian(0.2), -- m/s^2 on each axis
    map = function(a)
      local g = math.sqrt(a[1] ^ 2 + a[2] ^ 2 + a[3] ^ 2)
      if g < 0.6 * kG or g > 1.4 * kG then return nil end -- a knock, not gravity
      local angle = math.atan(a[1], a[3])
      local quarter = math.floor((angle + math.pi / 4) / (math.pi / 2)) % 4 + 1
      return {angle = angle, place = places[quarter]}
    end,
  }

  -- Forming: servo targets trimmed by the integral of the (small) remaining error.
  local trims = {pitch = 0, roll = 0, yaw = 0}
  local function hold(joint, name, goal, dt)
    local e = goal - joint:angle()
    if math.abs(e) < 0.02 then trims[name] = trims[name] + 3 * dt * e end
    joint:set_target(goal + trims[name])
  end

  local closed_at         -- when both end docks were first seen engaged
  local angle             -- last accepted angle round the loop
  local place
  local turned, history, n = 0, {}, 0 -- unwrapped turn in the rolling direction, its recent values
  local steps = 0

  function self.angle() return angle end
  function self.closed() return closed_at ~= nil end

  function self.step(dt, goal_rate)
    if not closed_at and front:engaged() and back:engaged() then closed_at = sim.time() end
    if not closed_at or sim.time() < closed_at + settle then
      hold(pitch, "pitch", -kHexagon, dt)
      hold(roll, "roll", 0, dt)
      hold(yaw, "yaw", 0, dt)
      return
    end

    local seen = module.sense("where")
    if seen then
      -- Rolling forward turns every module backwards round the loop (its angle decreases).
      if angle then turned = turned - direction * wrap(seen.angle - angle) end
      angle, place = seen.angle, seen.place
    end
    if not angle then return end

    n = n + 1
    history[n] = turned
    -- Rate over the last `window` seconds (over what there is, just after closing).
    local k = math.min(n - 1, math.max(1, math.floor(window / dt + 0.5)))
    local measured = k > 0 and (turned - history[n - k]) / (k * dt) or 0
    history[n - k - 1] = nil
    local lean = math.max(-max_lean, math.min(max_lean, gain * ((goal_rate or rate) - measured)))

    local joint = angle + math.pi / 6
    local bend = kHexagon + direction * lean * math.cos(2 * (joint - 0.75 * math.pi))
    pitch:set_target(-bend)
    roll:set_target(0)
    yaw:set_target(0)

    steps = steps + 1
    if params.verbose and steps % 30 == 0 then
      log(string.format("%-6s angle %6.1f deg  rate %5.2f rad/s  lean %5.1f deg  bend %5.1f deg", place,
                        math.deg(angle), measured, math.deg(lean), math.deg(bend)))
    end
  end

  return self
end

return M
