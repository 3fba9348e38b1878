-- A 10-module snake crawling 10 s at the world's defaults (one substep) keeps its modules on the
-- ground: no module rises faster than 0.8 m/s (measured 0.54; at two substeps 0.55), no dock
-- breaks and no dock carries 80 N (measured 57). When a motor reaches its rating the exact solver
-- sweeps the contacts again until they settle; with one sweep only, a module touching down while
-- its neighbours' motors saturated took the impulse that had stopped its whole rigid group and was
-- thrown up (2.4 m/s at 1 x 10, docks breaking at 99 N).
world.set{duration = 10}
world.ground{friction = 0.8}
local chain = require("snake_chain").build{n = 10, behavior = "behaviors/snake.lua"}
local lastZ, rise, riseAt, load = {}, 0, 0, 0
world.on_step(function(t)
  for i, m in ipairs(chain) do
    local z = m:position().z
    if lastZ[i] and (z - lastZ[i]) / world.dt() > rise then rise, riseAt = (z - lastZ[i]) / world.dt(), t end
    lastZ[i] = z
    local l = i < #chain and m:dock_load("back")
    if l and l.force > load then load = l.force end
  end
end)
world.on_end(function()
  local broken = 0
  for _, e in ipairs(world.events()) do if e.event == "broken" then broken = broken + 1 end end
  expect(broken == 0, broken .. " connections broke")
  expect(rise < 0.8, string.format("a module rose at %.2f m/s at t=%.2f s", rise, riseAt))
  expect(load < 80, string.format("largest dock load %.1f N", load))
  log(string.format("fastest rise %.2f m/s, largest dock load %.1f N", rise, load))
end)
