-- Distributed discovery of the configuration (worlds/discovery.lua): every module learns who is
-- docked to whom, by which docks, using nothing but dock messages (one hop per step), the way
-- link-state routing floods a network. The protocol is lua/linkstate.lua (a library any
-- behaviour can use); this behaviour publishes what it learns.
--
-- The map is published (module.publish("map", ...)) as a sorted array of "a.dock-b.dock"
-- strings (module ids, a < b), for the world to check against world.graph(), and as the number
-- of modules reachable (module.publish("size", n)).
--
-- params:
--   leave_at    seconds: at this time the module disables `leave_dock` (it undocks there)
--   leave_dock  the dock to let go (default "back")
local linkstate = require("linkstate")
local net = linkstate.new()
local left = false

function on_dock(dock, event)
  net:on_dock(dock, event)
end

function init()
  net:init()
end

function step(dt)
  if params.leave_at and not left and sim.time() >= params.leave_at then
    left = true
    module.dock(params.leave_dock or "back"):disable()
    log("undocking " .. (params.leave_dock or "back"))
  end
  net:receive()
  net:send()
  if net.changed then
    local map = net:map()
    module.publish("map", map.links)
    module.publish("size", #map.members)
  end
end
