-- The behaviour side of tests/api/types_world.lua: calls every behaviour function of the API
-- description with arguments of its declared types, checks what comes back (type_check.lua) and
-- publishes the names it checked and any mismatch for the world to collect.
local T = require("type_check")
local check = T.check

local jointName = module.joints()[1]
percepts = {tilt = {sensor = "accelerometer"}}
actions = {move = {joint = jointName}}

local steps = 0

local function publish()
  local names = {}
  for name in pairs(T.checked) do names[name] = true end
  module.publish("checked", names)
  module.publish("failures", T.failures)
end

function init()
  check("init", {})
  publish()
end

function on_dock(dock, event)
  check("on_dock", {dock, event})
  publish()
end

function step(dt)
  check("step", {dt})
  steps = steps + 1
  local j = check("module.joint", {jointName}, module.joint(jointName))
  check("module.joints", {}, module.joints())
  check("module.docks", {}, module.docks())
  local d = check("module.dock", {"front"}, module.dock("front"))
  check("module.type_data", {}, module.type_data())
  check("module.type_data", {module.type}, module.type_data(module.type))
  check("Joint:angle", {}, j:angle())
  check("Joint:velocity", {}, j:velocity())
  check("Joint:torque", {}, j:torque())
  check("Joint:saturated", {}, j:saturated())
  check("Joint:target", {}, j:target())
  check("Joint:limits", {}, j:limits())
  check("Joint:name", {}, j:name())
  if steps % 3 == 0 then
    check("Joint:set_velocity", {0.5}, j:set_velocity(0.5))
  elseif steps % 3 == 1 then
    check("Joint:free", {}, j:free())
  else
    check("Joint:set_target", {0.1}, j:set_target(0.1))
  end
  check("Dock:enabled", {}, d:enabled())
  check("Dock:engaged", {}, d:engaged())
  check("Dock:gender", {}, d:gender())
  check("Dock:name", {}, d:name())
  check("Dock:peer", {}, d:peer())
  if params.peer then
    local link = module.dock(params.peer)
    check("Dock:peer", {}, link:peer())
    check("Dock:send", {{n = steps, text = "hi"}}, link:send({n = steps, text = "hi"}))
    -- Undock and dock again once, so both sides see "disengaged" and "engaged" in on_dock.
    if steps == 10 and module.name == "a" then check("Dock:disable", {}, link:disable()) end
    if steps == 12 and module.name == "a" then check("Dock:enable", {}, link:enable()) end
  end
  check("Dock:send", {"nobody there"}, d:send("nobody there"))
  if steps == 5 then
    check("Dock:disable", {}, d:disable())
    check("Dock:enable", {}, d:enable())
  end
  check("module.receive", {}, module.receive())
  check("module.receive", {params.peer or "front"}, module.receive(params.peer or "front"))
  check("module.sensor", {"accelerometer"}, module.sensor("accelerometer"))
  check("module.sensor", {"joint:" .. jointName, "velocity"}, module.sensor("joint:" .. jointName, "velocity"))
  check("module.has_sensor", {"accelerometer"}, module.has_sensor("accelerometer"))
  check("module.has_sensor", {"no_such_sensor"}, module.has_sensor("no_such_sensor"))
  check("module.sense", {"tilt"}, module.sense("tilt"))
  check("module.act", {"move", 0.1}, module.act("move", 0.1))
  check("module.trace", {"steps", steps}, module.trace("steps", steps))
  check("module.publish", {"steps", steps}, module.publish("steps", steps))
  T.acceptsEach("module.trace", 2, function(v) module.trace("union", v) end)
  check("sim.time", {}, sim.time())
  check("sim.dt", {}, sim.dt())
  check("sim.random", {}, sim.random())
  check("sim.random", {6}, sim.random(6))
  check("sim.random", {1, 6}, sim.random(1, 6))
  check("sim.gaussian", {}, sim.gaussian())
  check("sim.gaussian", {0.0, 2.0}, sim.gaussian(0.0, 2.0))
  check("sim.stream", {"k"}, sim.stream("k"))
  publish()
end
