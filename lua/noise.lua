-- Noise models for percepts and actions: `local noise = require("noise")` (behaviours get it as
-- the global `noise`). Each constructor checks its parameters (an error names the calling line)
-- and returns a model; every percept or action using it gets its own instance (its own drift,
-- delay line, stuck state). Models work on numbers and, element by element, on vectors such as
-- {x, y, z}; booleans and strings pass through. All randomness comes from a seeded stream: each
-- percept's and action's own (sim.stream("percept:<name>"), "action:<name>"), which
-- rm3d_behaviour.lua hands to model.make(stream), so the order in which a behaviour senses or
-- acts never changes the numbers; a model made without one draws from the module's stream (sim).
local noise = {}
local Model = {}
Model.__index = Model

local function model(kind, make, params, nil_ok)
  -- nil_ok: the model also sees readings that are nil (a delay line still advances)
  return setmetatable({kind = kind, make = make, params = params, nil_ok = nil_ok or false}, Model)
end

local function check(cond, msg)
  if not cond then error(msg, 3) end
end

local function number(x, name, fn)
  -- level 3: number -> the constructor -> the behaviour line that called it
  if not (type(x) == "number" and x == x) then
    error(string.format("noise.%s: %s must be a number, got %s", fn, name, type(x)), 3)
  end
end

-- Applies f to a number, or to each number in an array/vector table (keys kept).
local function each(v, f)
  if type(v) == "number" then return f(v, 1) end
  if type(v) ~= "table" then return v end
  local out = {}
  for k, x in pairs(v) do out[k] = x end
  local n = #v
  if n > 0 then
    for i = 1, n do
      if type(v[i]) == "number" then out[i] = f(v[i], i) end
    end
    local keys = {"x", "y", "z"}
    if n == 4 then keys = {"w", "x", "y", "z"} end
    for i, k in ipairs(keys) do
      if v[k] ~= nil and i <= n then out[k] = out[i] end
    end
  end
  return out
end
noise.each = each

--- Adds N(0, sigma) to each value.
function noise.gaussian(sigma)
  number(sigma, "sigma", "gaussian")
  check(sigma >= 0, "noise.gaussian: sigma must not be negative, got " .. sigma)
  return model("gaussian", function(r)
    local rng = r or sim
    return function(v) return each(v, function(x) return x + rng.gaussian(0, sigma) end) end
  end, {sigma = sigma})
end

--- Adds a uniform value in [-half_width, half_width].
function noise.uniform(half_width)
  number(half_width, "half_width", "uniform")
  check(half_width >= 0, "noise.uniform: half_width must not be negative, got " .. half_width)
  return model("uniform", function(r)
    local rng = r or sim
    return function(v) return each(v, function(x) return x + (2 * rng.random() - 1) * half_width end) end
  end, {half_width = half_width})
end

--- Adds a constant offset (a number, or one per element).
function noise.bias(b)
  check(type(b) == "number" or type(b) == "table", "noise.bias: expected a number or a table of numbers")
  return model("bias", function()
    return function(v)
      return each(v, function(x, i) return x + (type(b) == "number" and b or (b[i] or 0)) end)
    end
  end, {bias = b})
end

--- A random walk: an offset that moves by N(0, sigma * sqrt(dt)) every step (sigma per sqrt s).
function noise.drift(sigma)
  number(sigma, "sigma", "drift")
  check(sigma >= 0, "noise.drift: sigma must not be negative, got " .. sigma)
  return model("drift", function(r)
    local rng = r or sim
    local offset, last = {}, nil
    return function(v)
      local t = sim.time()
      if last ~= t then
        -- the walk advances with time, not with reads: sigma * sqrt(time since the last read)
        local span = last and (t - last) or sim.dt()
        for i = 1, (type(v) == "table" and #v or 1) do
          offset[i] = (offset[i] or 0) + rng.gaussian(0, sigma * math.sqrt(span))
        end
        last = t
      end
      return each(v, function(x, i) return x + (offset[i] or 0) end)
    end
  end, {sigma = sigma})
end

--- A calibration error: an offset drawn once from N(0, sigma) (one per element) and kept.
function noise.offset(sigma)
  number(sigma, "sigma", "offset")
  check(sigma >= 0, "noise.offset: sigma must not be negative, got " .. sigma)
  return model("offset", function(r)
    local rng = r or sim
    local offset = {}
    return function(v)
      return each(v, function(x, i)
        if offset[i] == nil then offset[i] = rng.gaussian(0, sigma) end
        return x + offset[i]
      end)
    end
  end, {sigma = sigma})
end

--- A slowly wandering error: a first-order Gauss-Markov (Ornstein-Uhlenbeck) offset with standard
--- deviation `sigma` that forgets itself over `tau` seconds (correlation exp(-t / tau)); it
--- starts drawn from that spread. A servo's tracking error, a gyro's bias instability.
function noise.wander(sigma, tau)
  number(sigma, "sigma", "wander")
  number(tau, "tau", "wander")
  check(sigma >= 0, "noise.wander: sigma must not be negative, got " .. sigma)
  check(tau > 0, "noise.wander: tau must be a positive number of seconds, got " .. tau)
  return model("wander", function(r)
    local rng = r or sim
    local offset, last = {}, nil
    return function(v)
      local t = sim.time()
      if last ~= t then
        -- exact discretisation over the time since the last read: a = exp(-span / tau)
        local span = last and (t - last) or nil
        local n = type(v) == "table" and #v or 1
        for i = 1, n do
          if offset[i] == nil or span == nil then
            offset[i] = rng.gaussian(0, sigma)
          else
            local a = math.exp(-span / tau)
            offset[i] = a * offset[i] + rng.gaussian(0, sigma * math.sqrt(1 - a * a))
          end
        end
        last = t
      end
      return each(v, function(x, i) return x + (offset[i] or 0) end)
    end
  end, {sigma = sigma, tau = tau})
end

--- Reads nothing (nil) with probability p.
function noise.dropout(p)
  number(p, "p", "dropout")
  check(p >= 0 and p <= 1, "noise.dropout: p must be in [0, 1], got " .. p)
  return model("dropout", function(r)
    local rng = r or sim
    return function(v)
      if rng.random() < p then return nil end
      return v
    end
  end, {p = p})
end

--- Rounds to multiples of `step`.
function noise.quantise(step)
  number(step, "step", "quantise")
  check(step > 0, "noise.quantise: step must be positive, got " .. step)
  return model("quantise", function()
    return function(v) return each(v, function(x) return math.floor(x / step + 0.5) * step end) end
  end, {step = step})
end
noise.quantize = noise.quantise

--- Clamps into [lo, hi].
function noise.saturate(lo, hi)
  number(lo, "lo", "saturate")
  number(hi, "hi", "saturate")
  check(lo <= hi, "noise.saturate: lo must not exceed hi")
  return model("saturate", function()
    return function(v) return each(v, function(x) return math.max(lo, math.min(hi, x)) end) end
  end, {lo = lo, hi = hi})
end

--- The value from k steps earlier (nil for the first k steps). Assumes one read per step.
function noise.delay(k)
  check(math.type(k) == "integer" and k >= 0, "noise.delay: k must be a whole number of steps >= 0")
  return model("delay", function()
    local line, head = {}, 0
    return function(v)
      head = head + 1
      line[head] = v == nil and false or v
      local out = line[head - k]
      line[head - k - 1] = nil
      if out == false then return nil end
      return out
    end
  end, {k = k}, true)
end

--- Stuck-at failure: from time `at` (or, each step, with probability `rate`) the value freezes
--- at what it was then, or at `value` if given.
function noise.stuck(opts)
  check(type(opts) == "table", "noise.stuck: expected a table {at = seconds} or {rate = probability per step}")
  for k in pairs(opts) do
    check(k == "at" or k == "rate" or k == "value", "noise.stuck: unknown option '" .. tostring(k) .. "' (expected at, rate, value)")
  end
  check(opts.at ~= nil or opts.rate ~= nil, "noise.stuck: give `at` (seconds) or `rate` (probability per step)")
  if opts.rate then check(type(opts.rate) == "number" and opts.rate >= 0 and opts.rate <= 1, "noise.stuck: rate must be in [0, 1]") end
  if opts.at then check(type(opts.at) == "number" and opts.at >= 0, "noise.stuck: at must be a time >= 0") end
  return model("stuck", function(r)
    local rng = r or sim
    local stuck, held = false, nil
    return function(v)
      if not stuck and ((opts.at and sim.time() >= opts.at) or (opts.rate and rng.random() < opts.rate)) then
        stuck = true
        held = opts.value
        if held == nil then held = v end
      end
      if stuck then return held end
      return v
    end
  end, opts)
end

--- Several models applied in order.
function noise.compose(...)
  local models = {...}
  for i, m in ipairs(models) do
    check(getmetatable(m) == Model, "noise.compose: argument " .. i .. " is not a noise model")
  end
  local nil_ok = false
  for _, m in ipairs(models) do nil_ok = nil_ok or m.nil_ok end
  return model("compose", function(r)
    local fs = {}
    for i, m in ipairs(models) do fs[i] = m.make(r) end
    return function(v)
      for i, f in ipairs(fs) do
        if v ~= nil or models[i].nil_ok then v = f(v) end
      end
      return v
    end
  end, {models = models}, nil_ok)
end

--- True for what the constructors return.
function noise.is_model(m) return getmetatable(m) == Model end

return noise
