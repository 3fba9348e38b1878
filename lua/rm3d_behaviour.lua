-- Percepts and actions: loaded into every behaviour VM before the behaviour itself. A behaviour
-- declares them as global tables and uses them through module.sense and module.act:
--
--   percepts = { tilt = { sensor = "accelerometer", noise = noise.gaussian(0.05),
--                         map = function(a) return a[1] end } }
--   actions  = { lift = { joint = "pitch", noise = noise.gaussian(0.01) } }
--   ... module.sense("tilt") ... module.act("lift", 0.5) ...
--
-- Percept fields: sensor (a sensor of the module type: "accelerometer", "joint:pitch",
-- "dock:front", "range:front", ...), field ("velocity" for a joint's speed), noise (a model or a
-- list applied in order), map (a function turning the noisy reading into any Lua value). A
-- percept is read at most once per step (later reads in the same step return the same value).
-- Action fields: joint (with mode "target", the default, or "velocity") or dock (a true value
-- enables it, false disables it), noise, map (applied to the command before the noise).
local noise = require("noise")
_G.noise = noise

local sensor, has_sensor = module.sensor, module.has_sensor
local state = {percepts = nil, actions = nil, p = {}, a = {}}

local function fail(msg) error(msg, 0) end

local function keys_sorted(t)
  local ks = {}
  for k in pairs(t) do ks[#ks + 1] = k end
  table.sort(ks, function(a, b) return tostring(a) < tostring(b) end)
  return ks
end

local function check_keys(where, spec, allowed)
  for _, k in ipairs(keys_sorted(spec)) do
    if not allowed[k] then
      local names = keys_sorted(allowed)
      fail(string.format("%s: unknown field '%s' (expected one of: %s)", where, tostring(k), table.concat(names, ", ")))
    end
  end
end

-- `key` names the random stream the noise draws from ("percept:tilt", "action:lift"): one per
-- percept or action, so call order (pairs() over the actions, say) never changes the numbers.
local function pipeline(where, spec, key)
  local stages, nil_ok = {}, {}
  local rng = sim.stream(key)
  local n = spec.noise
  if n ~= nil then
    if noise.is_model(n) then
      stages[1], nil_ok[1] = n.make(rng), n.nil_ok
    elseif type(n) == "table" then
      for i, m in ipairs(n) do
        if not noise.is_model(m) then fail(string.format("%s: noise[%d] is not a noise model", where, i)) end
        stages[i], nil_ok[i] = m.make(rng), m.nil_ok
      end
    else
      fail(where .. ": noise must be a noise model (noise.gaussian(...), ...) or a list of them")
    end
  end
  if spec.map ~= nil and type(spec.map) ~= "function" then fail(where .. ": map must be a function") end
  return function(v)
    for i, f in ipairs(stages) do
      if v ~= nil or nil_ok[i] then v = f(v) end  -- a nil still advances a delay line
    end
    return v
  end
end

local kPerceptFields = {sensor = true, field = true, noise = true, map = true}
local kActionFields = {joint = true, dock = true, mode = true, noise = true, map = true}

local function build()
  state.percepts, state.actions = rawget(_G, "percepts"), rawget(_G, "actions")
  state.p, state.a = {}, {}
  if state.percepts ~= nil then
    if type(state.percepts) ~= "table" then fail("percepts: expected a table of percept declarations") end
    for _, name in ipairs(keys_sorted(state.percepts)) do
      local spec, where = state.percepts[name], "percepts." .. tostring(name)
      if type(spec) ~= "table" then fail(where .. ": expected a table {sensor = ..., noise = ..., map = ...}") end
      check_keys(where, spec, kPerceptFields)
      if type(spec.sensor) ~= "string" then fail(where .. ": sensor must be a sensor name such as \"accelerometer\"") end
      local ok, list = has_sensor(spec.sensor)
      if not ok then fail(string.format("%s: no sensor '%s' on a %s (it has: %s)", where, spec.sensor, module.type, list)) end
      if spec.field ~= nil and spec.field ~= "velocity" then fail(where .. ": field must be \"velocity\" (joints only)") end
      state.p[name] = {spec = spec, apply = pipeline(where, spec, "percept:" .. tostring(name)), stamp = nil, value = nil}
    end
  end
  if state.actions ~= nil then
    if type(state.actions) ~= "table" then fail("actions: expected a table of action declarations") end
    for _, name in ipairs(keys_sorted(state.actions)) do
      local spec, where = state.actions[name], "actions." .. tostring(name)
      if type(spec) ~= "table" then fail(where .. ": expected a table {joint = ..., noise = ...}") end
      check_keys(where, spec, kActionFields)
      local target
      if spec.joint ~= nil then
        local ok, j = pcall(module.joint, spec.joint)
        if not ok then fail(string.format("%s: no joint '%s' on a %s (it has: %s)", where, tostring(spec.joint), module.type,
                                          table.concat(module.joints(), ", "))) end
        local mode = spec.mode or "target"
        if mode ~= "target" and mode ~= "velocity" then fail(where .. ": mode must be \"target\" or \"velocity\"") end
        target = mode == "velocity" and function(v) j:set_velocity(v) end or function(v) j:set_target(v) end
      elseif spec.dock ~= nil then
        local ok, d = pcall(module.dock, spec.dock)
        if not ok then fail(string.format("%s: no dock '%s' on a %s (it has: %s)", where, tostring(spec.dock), module.type,
                                          table.concat(module.docks(), ", "))) end
        target = function(v) if v then d:enable() else d:disable() end end
      else
        fail(where .. ": give the joint or the dock it drives")
      end
      state.a[name] = {spec = spec, apply = pipeline(where, spec, "action:" .. tostring(name)), target = target}
    end
  end
end

--- Checks the declarations (the engine calls this after loading the behaviour).
function module.__check() build() end

--- module.sense(name) -> the percept's value this step (noise and map applied), or nil
function module.sense(name)
  if rawget(_G, "percepts") ~= state.percepts then build() end
  local p = state.p[name]
  if p == nil then error(string.format("module.sense: no percept named '%s' (declare it in the global table `percepts`)", tostring(name)), 2) end
  local t = sim.time()
  if p.stamp == t then return p.value end
  local v = p.apply(sensor(p.spec.sensor, p.spec.field))
  if v ~= nil and p.spec.map then v = p.spec.map(v) end
  p.stamp, p.value = t, v
  return v
end

--- For the viewer's inspector: each percept's last value, one per line.
function module.__describe()
  local lines = {}
  for _, name in ipairs(keys_sorted(state.p)) do
    local v = state.p[name].value
    local text
    if type(v) == "table" then
      local parts = {}
      for _, k in ipairs(keys_sorted(v)) do parts[#parts + 1] = tostring(k) .. "=" .. tostring(v[k]) end
      text = "{" .. table.concat(parts, ", ") .. "}"
    else
      text = tostring(v)
    end
    lines[#lines + 1] = tostring(name) .. " = " .. text
  end
  return table.concat(lines, "\n")
end

--- module.act(name, value): the command through the action's map and noise to its joint or dock
function module.act(name, value)
  if rawget(_G, "actions") ~= state.actions then build() end
  local a = state.a[name]
  if a == nil then error(string.format("module.act: no action named '%s' (declare it in the global table `actions`)", tostring(name)), 2) end
  local v = value
  if a.spec.map then v = a.spec.map(v) end
  v = a.apply(v)
  if v ~= nil then a.target(v) end  -- a dropped command does nothing
end
