-- For tests/worlds/noise_models.lua: the statistics and the exact behaviour of every noise model in
-- lua/noise.lua, from many samples of the module's own seeded stream. Any failed check is an
-- error (the world sees it as m:error()); the figures are logged. When every check has run the
-- module disables its "back" dock, which the world reads as "all checks ran".
--
-- Most models are sampled directly (model.make() gives one instance, a function of the clean
-- value), one model per step to stay well inside the per-call instruction budget. Drift, wander and
-- stuck depend on time, so they are sampled once per step over `kDriftT` seconds. Percepts and
-- actions then check that a list of models is applied in order, on vectors too.
local kN = 40000          -- samples per model
local kDriftN = 400       -- independent drift instances
local kDriftT = 2.0       -- seconds of drift
local kDriftSigma = 0.5   -- per sqrt(second)
local kWanderSigma, kWanderTau = 0.3, 2.0  -- wander: spread and seconds

-- A percept list is applied in order: saturate then bias differs from bias then saturate (the
-- chassis rides at z = 0.04; both clamp it into [0, 0.01]).
percepts = {
  sat_bias = {sensor = "position", noise = {noise.saturate(0, 0.01), noise.bias(1)}},
  bias_sat = {sensor = "position", noise = {noise.bias(1), noise.saturate(0, 0.01)}},
  lossy = {sensor = "range:front", noise = noise.dropout(0.5), map = function(d) return {d = d} end},
}
actions = {
  shifted = {joint = "wheel_fl", noise = noise.bias(0.5)},                    -- a servo target + 0.5
  scaled = {joint = "wheel_fr", map = function(v) return 2 * v end, noise = noise.saturate(-1, 1)},
  lost = {joint = "wheel_rl", noise = noise.dropout(1)},                       -- never arrives
}

local function check(cond, fmt, ...) if not cond then error(string.format(fmt, ...), 2) end end

local function stats(xs)
  local n, s = #xs, 0
  for i = 1, n do s = s + xs[i] end
  local mean, v = s / n, 0
  for i = 1, n do v = v + (xs[i] - mean) ^ 2 end
  return mean, math.sqrt(v / (n - 1))
end

local function samples(model, input, n)
  local f, out = model.make(), {}
  for i = 1, n or kN do out[i] = f(input) end
  return out
end

local checks = 0
local function ok(what, fmt, ...)
  checks = checks + 1
  log(string.format("ok %-10s " .. (fmt or ""), what, ...))
end

-- One model per step (stage i runs in step i).
local stages = {
  function()  -- gaussian: mean 0, std sigma within 3%; vectors noisy per element; others pass
    local sigma = 0.2
    local xs = samples(noise.gaussian(sigma), 1.0)
    local mean, std = stats(xs)
    check(math.abs(mean - 1.0) < 0.005, "gaussian: mean offset %.5f (expected ~0)", mean - 1.0)
    check(math.abs(std / sigma - 1) < 0.03, "gaussian: std %.5f, sigma %.3f (more than 3%% off)", std, sigma)
    local f = noise.gaussian(sigma).make()
    local v = f({1, 2, 3, x = 1, y = 2, z = 3})
    check(v[1] ~= 1 and v[2] ~= 2 and v[3] ~= 3, "gaussian: every element of a vector gets noise")
    check(v.x == v[1] and v.y == v[2] and v.z == v[3], "gaussian: a vector's x, y, z keys follow its elements")
    check(f(true) == true and f("s") == "s", "gaussian: booleans and strings pass through")
    check(noise.gaussian(0).make()(0.123) == 0.123, "gaussian(0) changes nothing")
    ok("gaussian", "N=%d mean offset %+.5f std %.5f (sigma %.3f, %+.2f%%)", kN, mean - 1.0, std, sigma, 100 * (std / sigma - 1))
  end,
  function()  -- uniform: inside [-h, h], reaching both ends, mean 0, std h/sqrt(3)
    local h = 0.5
    local xs = samples(noise.uniform(h), 2.0)
    local lo, hi = math.huge, -math.huge
    for i = 1, #xs do
      xs[i] = xs[i] - 2.0
      lo, hi = math.min(lo, xs[i]), math.max(hi, xs[i])
    end
    local mean, std = stats(xs)
    check(lo >= -h and hi <= h, "uniform: a sample outside [-%g, %g]: [%.6f, %.6f]", h, h, lo, hi)
    check(lo < -0.99 * h and hi > 0.99 * h, "uniform: samples should reach both ends, got [%.4f, %.4f]", lo, hi)
    check(math.abs(mean) < 0.007, "uniform: mean %.5f (expected ~0)", mean)
    check(math.abs(std / (h / math.sqrt(3)) - 1) < 0.03, "uniform: std %.5f, expected %.5f", std, h / math.sqrt(3))
    ok("uniform", "N=%d range [%.4f, %.4f] mean %+.5f std %.5f (h/sqrt 3 = %.5f)", kN, lo, hi, mean, std, h / math.sqrt(3))
  end,
  function()  -- bias: exact offsets, one per element when given a table
    local f = noise.bias(0.25).make()
    for _, x in ipairs{0, 1.5, -3, 1e6} do check(f(x) == x + 0.25, "bias: %g + 0.25 gave %.17g", x, f(x)) end
    local g = noise.bias({0.1, -0.2}).make()
    local v = g({1, 1, 1, x = 1, y = 1, z = 1})
    check(v[1] == 1 + 0.1 and v[2] == 1 - 0.2 and v[3] == 1, "bias: per-element offsets (missing ones are 0)")
    check(v.x == v[1] and v.y == v[2] and v.z == v[3], "bias: a vector's keys follow its elements")
    ok("bias", "exact")
  end,
  function()  -- offset: drawn once per instance and kept; across instances N(0, sigma); per element
    local sigma, n, xs = 0.2, 4000, {}
    for i = 1, n do
      local f = noise.offset(sigma).make()
      local a = f(1)
      check(f(1) == a and math.abs(f(5) - (a + 4)) < 1e-12, "offset: instance %d did not keep its offset", i)
      xs[i] = a - 1
    end
    local mean, std = stats(xs)
    check(math.abs(std / sigma - 1) < 0.05, "offset: std %.4f across %d instances, sigma %.2f", std, n, sigma)
    check(math.abs(mean) < 4 * sigma / math.sqrt(n), "offset: mean %.4f", mean)
    local g = noise.offset(sigma).make()
    local v = g({0, 0, 0})
    local w = g({1, 1, 1})
    check(v[1] ~= v[2] and w[1] == v[1] + 1 and w[2] == v[2] + 1 and w[3] == v[3] + 1, "offset: one kept offset per element")
    check(noise.offset(0).make()(3) == 3, "offset(0) changed a value")
    ok("offset", "%d instances: std %.4f (sigma %.2f), mean %+.4f; kept, one per element", n, std, sigma, mean)
  end,
  function()  -- dropout: nil fraction p within 1%; p = 0 never, p = 1 always
    local p = 0.2
    local f, lost = noise.dropout(p).make(), 0
    for _ = 1, kN do if f(1) == nil then lost = lost + 1 end end
    check(math.abs(lost / kN - p) < 0.01, "dropout: nil fraction %.4f, p %.2f", lost / kN, p)
    local never, always = noise.dropout(0).make(), noise.dropout(1).make()
    for _ = 1, 1000 do
      check(never(1) == 1, "dropout(0) dropped a value")
      check(always(1) == nil, "dropout(1) let a value through")
    end
    ok("dropout", "N=%d nil fraction %.4f (p %.2f)", kN, lost / kN, p)
  end,
  function()  -- quantise: exact multiples of the step, within half a step of the input
    for _, q in ipairs{0.25, 0.1, 3} do
      local f = noise.quantise(q).make()
      for _ = 1, 5000 do
        local x = (sim.random() - 0.5) * 20
        local y = f(x)
        local k = math.floor(y / q + 0.5)
        check(y == k * q, "quantise(%g): %.17g is not a multiple", q, y)
        check(math.abs(y - x) <= q / 2 + 1e-12, "quantise(%g): %.6f -> %.6f is more than half a step", q, x, y)
      end
    end
    check(noise.quantize == noise.quantise, "quantize is quantise")
    ok("quantise", "steps 0.25, 0.1, 3: exact multiples within half a step")
  end,
  function()  -- saturate: clamped into [lo, hi], values inside unchanged
    local f = noise.saturate(-1, 2).make()
    for _ = 1, 5000 do
      local x = (sim.random() - 0.5) * 10
      local y = f(x)
      check(y >= -1 and y <= 2, "saturate: %.6f -> %.6f outside [-1, 2]", x, y)
      check((x < -1 and y == -1) or (x > 2 and y == 2) or (x >= -1 and x <= 2 and y == x),
            "saturate: %.6f -> %.6f", x, y)
    end
    ok("saturate", "clamped into [-1, 2]")
  end,
  function()  -- delay: an exact k-step lag, nil for the first k reads, nils in the sequence kept
    for _, k in ipairs{0, 1, 3, 10} do
      local f = noise.delay(k).make()
      for i = 1, 50 do
        local y = f(i * 1.5)
        if i <= k then check(y == nil, "delay(%d): read %d should be nil, got %s", k, i, tostring(y))
        else check(y == (i - k) * 1.5, "delay(%d): read %d gave %s, expected %g", k, i, tostring(y), (i - k) * 1.5) end
      end
    end
    local f = noise.delay(2).make()
    local seq, want = {1, false, 3, 4, 5}, {nil, nil, 1, nil, 3}
    for i, v in ipairs(seq) do
      local y = f(v or nil)
      check(y == want[i], "delay(2) with a nil in the sequence: read %d gave %s", i, tostring(y))
    end
    ok("delay", "k = 0, 1, 3, 10: exact lag")
  end,
  function()  -- compose: models apply in order
    local sat_bias = noise.compose(noise.saturate(0, 1), noise.bias(0.5)).make()
    local bias_sat = noise.compose(noise.bias(0.5), noise.saturate(0, 1)).make()
    check(sat_bias(2) == 1.5 and sat_bias(-1) == 0.5 and sat_bias(0.25) == 0.75, "compose: saturate then bias")
    check(bias_sat(2) == 1 and bias_sat(-1) == 0 and bias_sat(0.25) == 0.75, "compose: bias then saturate")
    local q_b = noise.compose(noise.quantise(1), noise.bias(0.25)).make()
    local b_q = noise.compose(noise.bias(0.25), noise.quantise(1)).make()
    check(q_b(0.3) == 0.25 and b_q(0.3) == 1, "compose: quantise and bias in either order")
    check(noise.compose(noise.dropout(1), noise.bias(1)).make()(3) == nil, "compose: a dropout ends the chain")
    local ok_, err = pcall(noise.compose, noise.bias(1), 5)
    check(not ok_ and tostring(err):find("argument 2 is not a noise model", 1, true), "compose: bad argument: %s", tostring(err))
    ok("compose", "saturate(0,1)+bias(0.5): 2 -> 1.5; bias+saturate: 2 -> 1")
  end,
}

-- Time-dependent models, sampled once per step.
local wander, wander0 = {}, {}
local drift, drift_f, stuck_at, stuck_value, stuck_one, stuck_never = {}, nil, nil, nil, nil, nil
local kStuckAt = 0.5
local stuck_seen = {}

function init()
  for i = 1, kDriftN do drift[i] = noise.drift(kDriftSigma).make() end
  drift_f = noise.drift(kDriftSigma).make()
  for i = 1, kDriftN do wander[i] = noise.wander(kWanderSigma, kWanderTau).make() end
  stuck_at = noise.stuck({at = kStuckAt}).make()
  stuck_value = noise.stuck({at = kStuckAt, value = -7}).make()
  stuck_one = noise.stuck({rate = 1}).make()
  stuck_never = noise.stuck({rate = 0}).make()
end

local step_no, done = 0, false

function step(dt)
  if done then return end
  step_no = step_no + 1
  local t = sim.time()
  if stages[step_no] then stages[step_no]() end

  -- drift: every instance read once per step while t <= kDriftT
  local reads = step_no
  if t <= kDriftT + 1e-9 then
    local a = drift_f(10)
    check(drift_f(10) == a, "drift: a second read in the same step should not move it")
    local offsets = {}
    for i = 1, kDriftN do offsets[i] = drift[i](0) end
    if t + dt > kDriftT + 1e-9 then  -- the last read: compare with sigma * sqrt(reads * dt)
      local mean, std = stats(offsets)
      local expect_std = kDriftSigma * math.sqrt(reads * dt)
      check(math.abs(std / expect_std - 1) < 0.15, "drift: std %.4f after %d steps, expected %.4f (15%%)", std, reads, expect_std)
      check(math.abs(mean) < 4 * expect_std / math.sqrt(kDriftN), "drift: mean %.4f across instances", mean)
      ok("drift", "%d instances, %d steps (%.3f s): std %.4f, sigma*sqrt(T) %.4f (%+.1f%%), mean %+.4f",
         kDriftN, reads, reads * dt, std, expect_std, 100 * (std / expect_std - 1), mean)
    end
  end

  -- wander: stationary (std sigma at the first read and the last), correlated exp(-T / tau)
  if t <= kDriftT + 1e-9 then
    local now = {}
    for i = 1, kDriftN do now[i] = wander[i](0) end
    check(wander[1](0) == now[1], "wander: a second read in the same step should not move it")
    if step_no == 1 then
      wander0 = now
      local _, std = stats(now)
      check(math.abs(std / kWanderSigma - 1) < 0.15, "wander: std %.4f at the start, sigma %.2f", std, kWanderSigma)
    elseif t + dt > kDriftT + 1e-9 then
      local m0, s0 = stats(wander0)
      local m1, s1 = stats(now)
      local c = 0
      for i = 1, kDriftN do c = c + (wander0[i] - m0) * (now[i] - m1) end
      c = c / (kDriftN * s0 * s1)
      local want = math.exp(-(t - dt) / kWanderTau)  -- (the first read was at one step)
      check(math.abs(s1 / kWanderSigma - 1) < 0.15, "wander: std %.4f after %.2f s, sigma %.2f", s1, t, kWanderSigma)
      check(math.abs(c - want) < 0.15, "wander: correlation %.3f over %.2f s, expected %.3f", c, t - dt, want)
      ok("wander", "%d instances: std %.4f then %.4f (sigma %.2f); correlation %.3f over %.2f s (exp(-T/tau) %.3f)",
         kDriftN, s0, s1, kWanderSigma, c, t - dt, want)
    end
  end

  -- stuck: the input is the step number; frozen from the first step at t >= kStuckAt
  local a, b, c, d = stuck_at(step_no), stuck_value(step_no), stuck_one(step_no), stuck_never(step_no)
  if t < kStuckAt - 1e-9 then
    check(a == step_no and b == step_no, "stuck{at}: should follow the input before t=%g", kStuckAt)
  else
    stuck_seen.first = stuck_seen.first or step_no
    check(a == stuck_seen.first, "stuck{at}: holds %s, expected %d (the value at t=%g)", tostring(a), stuck_seen.first, kStuckAt)
    check(b == -7, "stuck{at, value = -7}: holds %s", tostring(b))
  end
  check(c == 1, "stuck{rate = 1}: should hold the first value, got %s", tostring(c))
  check(d == step_no, "stuck{rate = 0}: should never stick")

  -- percepts: a list applies in order (and on vectors, keys follow elements)
  local sb, bs = module.sense("sat_bias"), module.sense("bias_sat")
  check(sb.z == 1.01 and sb[3] == 1.01, "percept saturate(0, 0.01) then bias(1): z = %s", tostring(sb.z))
  check(bs.z == 0.01 and bs[3] == 0.01, "percept bias(1) then saturate(0, 0.01): z = %s", tostring(bs.z))
  check(rawequal(module.sense("lossy"), module.sense("lossy")), "a percept reads once per step")

  -- actions: map, then noise, then the joint; a dropped command leaves the joint alone
  module.act("shifted", 0.25)
  check(module.joint("wheel_fl"):target() == 0.75, "action bias(0.5): target %s", tostring(module.joint("wheel_fl"):target()))
  module.act("scaled", 0.75)
  check(module.joint("wheel_fr"):target() == 1, "action map x2 then saturate(-1, 1): target %s", tostring(module.joint("wheel_fr"):target()))
  local before = module.joint("wheel_rl"):target()
  module.act("lost", 0.3)
  check(module.joint("wheel_rl"):target() == before, "action with dropout(1) changed the joint")

  if t > kDriftT + 1e-9 and step_no > #stages then
    check(checks == #stages + 2, "%d of %d model checks ran", checks, #stages + 2)
    ok("stuck", "at = %g froze step %d's value; value = -7; rate = 1 froze the first; rate = 0 never", kStuckAt, stuck_seen.first)
    ok("percepts", "lists apply in order (1.01 vs 0.01); actions: map, noise, dropout")
    module.dock("back"):disable()
    done = true
  end
end
