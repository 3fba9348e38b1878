-- Docks, undocks and docks again (worlds/dock_pair.lua): once the dock named params.dock has
-- latched, the module holds the connection for params.hold seconds, disables the dock (the
-- connection is released), waits params.apart seconds and enables it again, so the capture
-- joint draws the faces back together and they latch a second time. Logs each event.
local dock = module.dock(params.dock or "front")
local hold, apart = params.hold or 1.0, params.apart or 1.0
local latched, released   -- times
local cycles = 0

function on_dock(d, event)
  if d:name() ~= dock:name() then return end
  log(string.format("%s: %s", d:name(), event))
  if event == "engaged" then
    latched = sim.time()
    cycles = cycles + 1
    module.publish("latches", cycles)
  end
end

function step(dt)
  local t = sim.time()
  if latched and cycles == 1 and not released and t - latched >= hold then
    dock:disable()
    released = t
  elseif released and dock:enabled() == false and t - released >= apart then
    dock:enable()
  end
end
