-- Self-reconfiguration: the modules of a robot learn its shape from dock messages
-- (lua/linkstate.lua), agree that every one of them holds the same map (lua/agree.lua, an echo
-- wave from the module with the smallest id), and then each computes the same plan from that map
-- to the target shape (lua/reconfig.lua) and the same steps that carry it out
-- (lua/lay_retrieve.lua: from a snake on the ground to a chain with one-module legs, and back;
-- lua/atron_moves.lua: ATRONs, by half turns of a hemisphere), with no global state. The steps run by messages through the docks; each is checked as it runs (a joint
-- that cannot reach its angle, a crawl that does not bring a socket to its leg, a connection
-- that breaks) and a failure stops every module that hears of it, with the reason.
--
-- Published (module.publish, for the world script and the HTML page):
--   plan        the plan as text (reconfig.format), the same on every module
--   digest      the committed map's digest
--   role        this module's role in the target
--   ops         the numbers of the plan's operations this module takes part in
--   committed   the time this module committed (s)
--   steps       the steps as text (lay_retrieve.format), the same on every module
--   reconfigured  the time this module saw the last step of a target's steps finish (s)
--   stage       the target under way (1, 2, ...), and finished: the last target whose steps finished
--   failed      why the steps stopped (the first failure heard of)
--   messages    messages this module has sent
--   error       why no plan could be made from the committed map (its part of the robot has other
--               modules than the target: a different number, or of other types), or why the
--               plan cannot be carried out (the shapes are not a snake and a legged chain)
--
-- params:
--   target   the target shape: {modules = {...}, connections = {...}} as reconfig.shape takes it
--   targets  shapes to become one after another (after `target`, if given): snake to walker to
--            snake is {targets = {walker, snake}}; before each, the modules agree on the map again
--   quiet    steps the leader's map must be unchanged before it asks (default: the modules in it + 2)
--   execute  false: agree and plan only, move nothing (default true)
--   walk     metres: once built, the walker trots this far forward (lua/walker_gait.lua)
--   noise    true (or {proximity = m, heading = per quaternion element, position = m, joints = rad}):
--            gaussian noise on the sensors the steps read and on every joint target; the table may
--            add joint_offset = rad (a calibration error per joint, drawn once) and joint_wander =
--            rad with joint_wander_tau = s (a tracking error that wanders, default 1 s)
--   leave_at, leave_dock   seconds, and a dock (default "back"): this module undocks there at that
--            time (to try the agreement with the shape changing under it)
local linkstate = require("linkstate")
local agree = require("agree")
local reconfig = require("reconfig")
local layRetrieve = require("lay_retrieve")
local atronMoves = require("atron_moves")
local gait = require("walker_gait")

-- The targets, one after another: params.target, then each of params.targets.
local targets = {}
if params.target ~= nil then
  if type(params.target) ~= "table" then
    error("params.target: expected a shape {modules = ..., connections = ...} (lua/reconfig.lua), got " ..
          type(params.target))
  end
  targets[1] = reconfig.shape(params.target)  -- checked here, before any step
end
if params.targets ~= nil and type(params.targets) ~= "table" then
  error("params.targets: expected a list of shapes, got " .. type(params.targets))
end
for i, t in ipairs(params.targets or {}) do
  if type(t) ~= "table" then error("params.targets[" .. i .. "]: expected a shape, got " .. type(t)) end
  targets[#targets + 1] = reconfig.shape(t)
end
if #targets == 0 then error("params.target: expected a shape {modules = ..., connections = ...} (lua/reconfig.lua)") end
if params.walk ~= nil and (type(params.walk) ~= "number" or params.walk < 0) then
  error("params.walk: expected metres (a number, at least 0), got " .. tostring(params.walk))
end
if params.quiet ~= nil and (math.type(params.quiet) ~= "integer" or params.quiet < 1) then
  error("params.quiet: expected steps (a whole number, at least 1), got " .. tostring(params.quiet))
end
if params.leave_at ~= nil and type(params.leave_at) ~= "number" then
  error("params.leave_at: expected seconds (a number), got " .. tostring(params.leave_at))
end
local stage = 1  -- the target under way

-- Sensor and actuator noise (params.noise: true for the defaults below, or a table of them).
local kNoise = {proximity = 0.005, heading = 0.01, position = 0.005, joints = 0.02}
local sigma = {}
if params.noise ~= nil and params.noise ~= false then
  if params.noise ~= true and type(params.noise) ~= "table" then
    error("params.noise: expected true or a table {proximity =, heading =, position =, joints =}, got " ..
          type(params.noise))
  end
  for _, k in ipairs({"heading", "joint_offset", "joint_wander", "joint_wander_tau", "joints", "position",
                      "proximity"}) do  -- (in order: the first bad one is named)
    local default = kNoise[k]
    local v = default
    if params.noise ~= true then v = params.noise[k] end
    if k == "joint_wander_tau" and v ~= nil and not (type(v) == "number" and v > 0) then
      error("params.noise.joint_wander_tau: expected seconds (a number, more than 0), got " .. tostring(v))
    end
    if v ~= nil and (type(v) ~= "number" or v < 0) then
      error("params.noise." .. k .. ": expected a standard deviation (a number, at least 0), got " .. tostring(v))
    end
    sigma[k] = v or 0
  end
  if sigma.joint_wander_tau == 0 then sigma.joint_wander_tau = 1 end
end

-- The docks' IR-style proximity and bearing (dock:<name>: {enabled, engaged, proximity, bearing}),
-- read while a crawl brings a socket to its leg or a tail to one (and steers it there), with
-- sigma.proximity m of noise on the distance (each dock its own stream; the bearing is exact).
-- The heading (a leg steers its trot by it: the orientation, with sigma.heading on each
-- quaternion element) and the position (the head measures the walk) are the SuperBot's oracle
-- sensors. Joint targets get sigma.joints rad of white noise, a calibration
-- offset and a wandering error (lua/noise.lua models).
percepts = {
  heading = {sensor = "orientation", noise = noise.gaussian(sigma.heading or 0)},
  position = {sensor = "position", noise = noise.gaussian(sigma.position or 0)},
}
for _, d in ipairs(module.docks()) do
  local rng = sim.stream("proximity:" .. d)
  percepts["dock:" .. d] = {sensor = "dock:" .. d, map = function(r)
    if r.proximity and (sigma.proximity or 0) > 0 then r.proximity = math.max(0, r.proximity + rng.gaussian(0, sigma.proximity)) end
    return r
  end}
end
actions = {}
for _, j in ipairs(module.joints()) do
  -- (Only the kinds asked for: each draws from the action's stream.)
  local models = {noise.gaussian(sigma.joints or 0)}
  if (sigma.joint_offset or 0) > 0 then models[#models + 1] = noise.offset(sigma.joint_offset) end
  if (sigma.joint_wander or 0) > 0 then models[#models + 1] = noise.wander(sigma.joint_wander, sigma.joint_wander_tau) end
  actions[j] = {joint = j, noise = models}
end
local io = {
  target = function(joint, rad) module.act(joint, rad) end,
  free = function(joint) module.joint(joint):free() end,  -- (the motor off: no command, no noise)
  proximity = function(dock) return module.sense("dock:" .. dock).proximity end,
  bearing = function(dock) return module.sense("dock:" .. dock).bearing end,
  heading = function() return gait.heading(module.sense("heading")) end,
  position = function() return module.sense("position") end,
}

local net = linkstate.new()
local agreement = agree.new(net, {quiet = params.quiet})
local plan, sentPublished, exec
local target = targets[1]

-- The shape of a committed map, by module name.
local function shapeOf(map)
  local mods, conns = {}, {}
  for _, id in ipairs(map.members) do
    local r = map.records[id]
    mods[r.name] = r.type
  end
  for _, e in ipairs(map.edges) do
    conns[#conns + 1] = {map.records[e[1]].name, e[2], map.records[e[3]].name, e[4]}
  end
  return reconfig.shape{modules = mods, connections = conns}
end

function on_dock(dock, event)
  net:on_dock(dock, event)
  if exec then exec:on_dock(dock, event) end
end

function init()
  net:init()
end

-- On commit: the plan, and (unless params.execute is false) the steps that carry it out.
local function commit()
  module.publish("digest", agreement.digest)
  module.publish("committed", sim.time())
  local now = shapeOf(agreement.map)
  local ok, result = pcall(reconfig.plan, now, target)
  if not ok then
    -- The robot this module is part of cannot become the target (another size, other types).
    plan = false
    module.publish("error", tostring(result))
    log("cannot plan: " .. tostring(result))
    return
  end
  plan = result
  local mine = {}
  for i, o in ipairs(plan.ops) do
    if o[1] == module.name or o[3] == module.name then mine[#mine + 1] = i end
  end
  module.publish("plan", reconfig.format(plan))
  module.publish("role", plan.role[module.name])
  module.publish("ops", mine)
  log(string.format("committed to map %s: role %s, %d of %d operations", agreement.digest,
                    plan.role[module.name], #mine, #plan.ops))
  if params.execute == false then return end
  if #plan.ops == 0 then
    -- Already the target: nothing to move.
    exec = {done = true, step = function() end, on_dock = function() end}
    return
  end
  -- The moves. ATRONs: half turns of a hemisphere (lua/atron_moves.lua). SuperBots: lay and
  -- retrieve (lua/lay_retrieve.lua); legs are interchangeable, so those steps may give the legs
  -- other roles than the plan's, and what they build must be the target all the same.
  local atrons = true
  for _, name in ipairs(now.names) do atrons = atrons and now.types[name] == "atron" end
  local moves = atrons and atronMoves or layRetrieve
  local steps, built
  if atrons then
    steps, built = atronMoves.compile(now, target, plan)
  else
    steps, built = layRetrieve.compile(now, target, {walk = params.walk})
  end
  if steps then
    local check = reconfig.plan(reconfig.shape(built), target)
    if #check.ops > 0 then steps, built = nil, "the steps would not build the target" end
  end
  if not steps then
    module.publish("error", "cannot carry the plan out: " .. built)
    log("cannot carry the plan out: " .. built)
    return
  end
  module.publish("steps", moves.format(steps))
  exec = moves.new(net, steps, {size = #agreement.map.members, io = io})
end

function step(dt)
  if params.leave_at and sim.time() >= params.leave_at and not state.left then
    state.left = true
    module.dock(params.leave_dock or "back"):disable()
    log("undocking " .. (params.leave_dock or "back"))
  end
  local parts = net:receive()
  agreement:step(parts)
  if exec then
    exec:step(parts)
    if exec.done and stage < #targets then
      -- On to the next target: agree again on the map the steps made, and plan from it.
      module.publish("finished", stage)
      module.publish("plan", nil)
      module.publish("steps", nil)
      stage = stage + 1
      target, plan, exec = targets[stage], nil, nil
      agreement:reset()
      module.publish("stage", stage)
    elseif exec.done and not state.finished then
      state.finished = true
      module.publish("finished", stage)
    end
  end
  if agreement.committed and plan == nil then commit() end
  net:send()
  if net.sent ~= sentPublished then
    module.publish("messages", net.sent)
    sentPublished = net.sent
  end
end
