-- For tests/engine/world/determinism_test.cpp: the snake gait of behaviors/snake.lua at full
-- amplitude from the start (a chain built in its pose by lua/snake_chain.lua), and the module
-- whose params.release is set lets its back dock go from step params.from to step params.to.
local gaits = require("gaits")
local joint = module.joint(params.joint or "pitch")

function step(dt)
  local t = sim.time()
  joint:set_target(gaits.wave(t, params.index, params.amplitude, params.period, params.lag))
  if params.index == params.release then
    local n = math.floor(t / dt + 0.5)
    local back = module.dock("back")
    if n >= params.from and n < params.to then back:disable() else back:enable() end
  end
end
