-- Obstacle avoidance for a Wheelbot from its one forward range sensor, read through a NOISY
-- percept (gaussian noise and dropouts), driving its wheels through noisy actions.
--
-- A single ray only sees what lies on the centre line, but the Wheelbot is 0.17 m wide across
-- its wheels, and a driven wheel that brushes a vertical face climbs it (the robot tips onto its
-- chassis). So the robot remembers what the ray has seen: every reading becomes a point in the
-- world (from the `position` and `orientation` sensors, also read with noise), kept for `memory`
-- seconds. While driving, the heading weaves gently (left and right wheels differ by +-`weave`,
-- a sine of period `weave_period`) so the ray sweeps a fan and fills the memory in front.
--
-- Two states:
--   drive  all wheels at `speed` (plus the weave). When a remembered point lies in the corridor
--          the body will sweep (half-width `width`, from the chassis front out to `safe`), or
--          the current reading is nearer than `safe`, it starts turning.
--   turn   spins in place (left wheels against right wheels at `turn_speed`), away from the side
--          with more obstacle points near the front, until the corridor is clear out to `clear`
--          and the ray agrees (`clear_reads` readings in a row beyond `clear`, or nils only),
--          then `extra` seconds more so the far edge of the body clears too. A turn that lasts
--          longer than `turn_limit` flips direction.
--
-- Nil readings mean "nothing within 2 m" or "dropped out"; they are treated conservatively:
-- a nil never erases a remembered point, so a dropout cannot hide a wall the robot was closing
-- on; only when nothing is remembered nearby do nils count as clear, and while turning only after
-- `clear_nils` in a row (with 5% dropouts six in a row happen once in 60 million reads).
--
-- params (all optional):
--   speed        wheel speed when driving, rad/s (default 6: 0.24 m/s with the 0.04 m wheels;
--                the motors' limit is 10)
--   safe         turn when an obstacle is nearer than this to the chassis front, m (default 0.3)
--   clear        a turn may end once the corridor is empty this far ahead, m (default 0.55)
--   width        half-width of the corridor kept free, m (default 0.15: the wheels reach 0.085)
--   turn_speed   wheel speed when spinning, rad/s (default 5)
--   weave        left/right wheel difference while driving, rad/s (default 2; 0 drives straight)
--   weave_period seconds per weave (default 2)
--   extra        seconds of turning after the way is clear (default 0.25)
--   memory       seconds a seen point is remembered (default 3)
--   sigma        range noise, m (default 0.01); dropout: probability of a nil reading (0.05)
--   act_sigma    noise on each wheel command, rad/s (default 0.1)
--   debug        log the state changes
local speed = params.speed or 6
local safe = params.safe or 0.3
local clear = params.clear or 0.55
local width = params.width or 0.15
local turn_speed = params.turn_speed or 5
local weave = params.weave or 2
local weave_period = params.weave_period or 2
local extra = params.extra or 0.25
local memory = params.memory or 3
local turn_limit = params.turn_limit or 6
local clear_reads, clear_nils = 3, 6
local kFront = 0.10          -- the range sensor sits on the chassis front face, 0.10 m ahead of the centre

percepts = {
  ahead = {
    sensor = "range:front",
    noise = {noise.gaussian(params.sigma or 0.01), noise.dropout(params.dropout or 0.05)},
    map = function(d) return {distance = d, near = d < safe, clear = d > clear} end,
  },
  place = {sensor = "position", noise = noise.gaussian(0.003)},
  heading = {
    sensor = "orientation",
    noise = noise.gaussian(0.002),
    map = function(q) return math.atan(2 * (q.w * q.z + q.x * q.y), 1 - 2 * (q.y * q.y + q.z * q.z)) end,
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

-- Remembered points: parallel arrays, oldest first (a ring would save little at ~200 points).
local px, py, pt = {}, {}, {}

local function remember(x, y, t)
  px[#px + 1], py[#py + 1], pt[#pt + 1] = x, y, t
  local drop = 0
  while drop < #pt and pt[drop + 1] < t - memory do drop = drop + 1 end
  if drop > 0 then
    local n = #pt
    for _, a in ipairs{px, py, pt} do
      table.move(a, drop + 1, n, 1)
      for i = n - drop + 1, n do a[i] = nil end
    end
  end
end

-- Looks at the remembered points from the robot at (x, y) heading h: returns the nearest
-- distance ahead of the chassis front inside the corridor (or nil), and a balance > 0 when more
-- points near the front lie on the left than on the right.
local function corridor(x, y, h, t)
  local c, s = math.cos(h), math.sin(h)
  local nearest, balance = nil, 0
  for i = 1, #pt do
    if pt[i] >= t - memory then
      local dx, dy = px[i] - x, py[i] - y
      local f, l = dx * c + dy * s - kFront, -dx * s + dy * c
      if f > -kFront and math.abs(l) < width and (nearest == nil or f < nearest) then nearest = f end
      if f > -kFront and f < clear and math.abs(l) < 2 * width then balance = balance + (l > 0 and 1 or -1) end
    end
  end
  return nearest, balance
end

state.mode, state.dir = "drive", 1    -- dir: +1 turns left (counter-clockwise), -1 right
state.good, state.nils = 0, 0         -- clear readings in a row; nils in a row
state.turn_start, state.clear_since = 0, nil
state.turns = 0

local function start_turn(t, balance, sweep)
  state.mode, state.turn_start, state.clear_since, state.good = "turn", t, nil, 0
  -- away from the side with more obstacle points; on a tie, away from where the ray was swinging
  if balance ~= 0 then state.dir = balance > 0 and -1 or 1 else state.dir = sweep > 0 and -1 or 1 end
  state.turns = state.turns + 1
  if params.debug then log("turn", state.dir > 0 and "left" or "right") end
end

function step(dt)
  local t = sim.time()
  local r, p, h = module.sense("ahead"), module.sense("place"), module.sense("heading")
  if r then
    state.nils = 0
    state.good = r.clear and state.good + 1 or 0
    if p and h then
      local reach = kFront + r.distance
      remember(p.x + reach * math.cos(h), p.y + reach * math.sin(h), t)
    end
  else
    state.nils = state.nils + 1
  end
  local nearest, balance = nil, 0
  if p and h then nearest, balance = corridor(p.x, p.y, h, t) end

  if state.mode == "drive" then
    local phase = 2 * math.pi * t / weave_period
    local sweep = math.sin(phase)   -- > 0 while the heading swings left (right wheels faster)
    if (r and r.near) or (nearest and nearest < safe) then
      start_turn(t, balance, sweep)
    else
      local w = weave * sweep
      drive(speed - w, speed + w)
      return
    end
  end

  -- turning: clear once the corridor is empty out to `clear` and the ray agrees
  local ray_clear = state.good >= clear_reads or state.nils >= clear_nils
  if state.clear_since == nil and ray_clear and (nearest == nil or nearest > clear) then
    state.clear_since = t
  end
  if state.clear_since and t - state.clear_since >= extra then
    state.mode = "drive"
    if params.debug then log("drive") end
    drive(speed, speed)
    return
  end
  if t - state.turn_start > turn_limit then
    state.dir, state.turn_start = -state.dir, t
  end
  drive(-state.dir * turn_speed, state.dir * turn_speed)
end
