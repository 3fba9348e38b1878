-- Counts on_dock events by kind and publishes the counts (module.publish), for docking tests.
local counts = {}
function on_dock(dock, event)
  counts[event] = (counts[event] or 0) + 1
  module.publish(event, counts[event])
end
function step(dt) end
