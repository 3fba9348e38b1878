-- Obstacle avoidance for a Wheelbot from its one forward range sensor, read through a NOISY
-- percept (gaussian noise and dropouts) and driving its wheels through noisy actions.
--
-- Two states:
--   drive  all four wheels at `speed`, the heading weaving gently (left and right wheels differ
--          by +-`weave` in a sine of period `weave_period`) so that the single ray sweeps a fan
--          instead of a line and sees obstacles a little off the centre line. When the percept
--          says an obstacle is nearer than `safe`, it starts turning.
--   turn   spins in place (left wheels against right wheels at `turn_speed`) away from the
--          obstacle until the way is clear: `clear_reads` readings in a row farther than `clear`,
--          then `extra` seconds more so the body (wider than the ray) clears the edge too. The
--          direction is the opposite of the way the ray was sweeping when the obstacle came into
--          view (the obstacle lies on that side); a turn that lasts longer than `turn_limit` flips
--          direction.
--
-- Nil readings mean "nothing within 2 m" or "dropped out"; they are treated conservatively:
--   driving: the last real reading stays in force, less the distance driven since, for up to
--            `hold` seconds of nils (so a dropout never hides a wall it was closing on);
--   turning: nils alone count as clear only after `clear_nils` in a row (5% dropouts make 6 in a
--            row a one-in-60-million event).
--
-- params (all optional):
--   speed        wheel speed when driving, rad/s (default 6: 0.24 m/s with the 0.04 m wheels;
--                the motors' limit is 10)
--   safe         turn when an obstacle is nearer than this, m from the chassis front (default 0.35)
--   clear        a turn may end once the way is this clear, m (default safe + 0.25)
--   turn_speed   wheel speed when spinning, rad/s (default 5)
--   weave        left/right wheel difference while driving, rad/s (default 1.5; 0 drives straight)
--   weave_period seconds per weave (default 2)
--   extra        seconds of turning after the way looks clear (default 0.3)
--   sigma        range noise, m (default 0.01); dropout: probability of a nil reading (0.05)
--   act_sigma    noise on each wheel command, rad/s (default 0.1)
local speed = params.speed or 6
local safe = params.safe or 0.35
local clear = params.clear or safe + 0.25
local turn_speed = params.turn_speed or 5
local weave = params.weave or 1.5
local weave_period = params.weave_period or 2
local extra = params.extra or 0.3
local hold = params.hold or 0.5
local clear_reads, clear_nils = 2, 6
local turn_limit = params.turn_limit or 6
local kWheelRadius = 0.04

percepts = {
  ahead = {
    sensor = "range:front",
    noise = {noise.gaussian(params.sigma or 0.01), noise.dropout(params.dropout or 0.05)},
    map = function(d) return {distance = d, near = d < safe, clear = d > clear} end,
  },
}

local act_sigma = params.act_sigma or 0.1
actions = {
  front_left = {joint = "wheel_fl", mode = "velocity", noise = noise.gaussian(act_sigma)},
  rear_left = {joint = "wheel_rl", mode = "velocity", noise = noise.gaussian(act_sigma)},
  front_right = {joint = "wheel_fr", mode = "velocity", noise = noise.gaussian(act_sigma)},
  rear_right = {joint = "wheel_rr", mode = "velocity", noise = noise.gaussian(act_sigma)},
}

local function drive(left, right)
  module.act("front_left", left)
  module.act("rear_left", left)
  module.act("front_right", right)
  module.act("rear_right", right)
end

-- state.mode: "drive" or "turn"; state.dir: +1 turns left (counter-clockwise), -1 right
state.mode, state.dir = "drive", 1
state.last_d, state.last_t = nil, nil   -- last real reading and when
state.nils, state.good = 0, 0           -- nils in a row; clear readings in a row (turning)
state.turn_start, state.clear_since = 0, nil
state.turns = 0

local function start_turn(t, sweep)
  state.mode, state.turn_start, state.clear_since = "turn", t, nil
  state.good = 0
  -- sweep > 0: the heading is swinging left, so the obstacle came into view on the left
  state.dir = sweep > 0 and -1 or 1
  state.turns = state.turns + 1
end

function step(dt)
  local t = sim.time()
  local r = module.sense("ahead")
  if r then
    state.last_d, state.last_t, state.nils = r.distance, t, 0
  else
    state.nils = state.nils + 1
  end

  if state.mode == "drive" then
    -- conservative distance: a real reading, or the last one less what we drove since
    local est
    if r then
      est = r.distance
    elseif state.last_d and t - state.last_t <= hold then
      est = state.last_d - speed * kWheelRadius * (t - state.last_t)
    end
    local phase = 2 * math.pi * t / weave_period
    local sweep = math.sin(phase)   -- > 0 while the heading swings left (right wheels faster)
    if est and est < safe then
      start_turn(t, weave > 0 and sweep or (sim.random() < 0.5 and 1 or -1))
    else
      local w = weave * math.sin(phase)
      drive(speed - w, speed + w)
      return
    end
  end

  -- turning
  if r then
    state.good = r.clear and state.good + 1 or 0
  end
  if state.clear_since == nil and (state.good >= clear_reads or state.nils >= clear_nils) then
    state.clear_since = t
  end
  if state.clear_since and t - state.clear_since >= extra then
    state.mode, state.last_d = "drive", nil
    drive(speed, speed)
    return
  end
  if t - state.turn_start > turn_limit then
    state.dir, state.turn_start = -state.dir, t
  end
  drive(-state.dir * turn_speed, state.dir * turn_speed)
end
