-- Self-reconfiguration, the agreement stage: the modules of a robot learn its shape from dock
-- messages (lua/linkstate.lua), agree that every one of them holds the same map (lua/agree.lua,
-- an echo wave from the module with the smallest id), and then each computes the same plan from
-- that map to the target shape (lua/reconfig.lua), with no global state and no further messages.
-- Each module knows its role in the target and the operations it takes part in.
--
-- Not yet: carrying the plan out (the moves, undocks and docks, with physics checks); this
-- behaviour holds its pose.
--
-- Published (module.publish, for the world script and the HTML page):
--   plan        the plan as text (reconfig.format), the same on every module
--   digest      the committed map's digest
--   role        this module's role in the target
--   ops         the numbers of the plan's operations this module takes part in
--   committed   the time this module committed (s)
--   messages    messages this module has sent
--   error       why no plan could be made from the committed map (its part of the robot has other
--               modules than the target: a different number, or of other types)
--
-- params:
--   target   the target shape: {modules = {...}, connections = {...}} as reconfig.shape takes it
--   quiet    steps the leader's map must be unchanged before it asks (default: the modules in it + 2)
--   leave_at, leave_dock   seconds, and a dock (default "back"): this module undocks there at that
--            time (to try the agreement with the shape changing under it)
local linkstate = require("linkstate")
local agree = require("agree")
local reconfig = require("reconfig")

if type(params.target) ~= "table" then
  error("params.target: expected a shape {modules = ..., connections = ...} (lua/reconfig.lua), got " ..
        type(params.target))
end
local target = reconfig.shape(params.target)  -- checked here, before any step
local net = linkstate.new()
local agreement = agree.new(net, {quiet = params.quiet})
local plan, sentPublished

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
end

function init()
  net:init()
end

function step(dt)
  if params.leave_at and sim.time() >= params.leave_at and not state.left then
    state.left = true
    module.dock(params.leave_dock or "back"):disable()
    log("undocking " .. (params.leave_dock or "back"))
  end
  agreement:step(net:receive())
  net:send()
  if agreement.committed and plan == nil then
    module.publish("digest", agreement.digest)
    module.publish("committed", sim.time())
    local ok, result = pcall(reconfig.plan, shapeOf(agreement.map), target)
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
  end
  if net.sent ~= sentPublished then
    module.publish("messages", net.sent)
    sentPublished = net.sent
  end
end
