-- behaviors/nod.lua: nods the front bracket (the tutorial's behaviour, docs/getting-started.md).
local pitch = module.joint("pitch")          -- look joints up once, not every step
local amplitude = params.amplitude or 0.5    -- params come from world.spawn
state.steps = state.steps or 0              -- in `state`: it survives a hot reload (a local restarts)

function step(dt)
  pitch:set_target(amplitude * math.sin(2 * math.pi * sim.time()))
  -- Once a second (t = 0, 1, 2, ...): count steps (an integer) rather than test sim.time() % 1,
  -- which floating point makes true on two steps in a row now and then.
  if state.steps % math.floor(1 / dt + 0.5) == 0 then log(string.format("pitch is %.3f rad", pitch:angle())) end
  state.steps = state.steps + 1
end
