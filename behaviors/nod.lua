-- behaviors/nod.lua: nods the front bracket (the README tutorial's behaviour).
local pitch = module.joint("pitch")          -- look joints up once, not every step
local amplitude = params.amplitude or 0.5    -- params come from world.spawn

function step(dt)
  pitch:set_target(amplitude * math.sin(2 * math.pi * sim.time()))
  if sim.time() % 1 < dt then log("pitch is", pitch:angle()) end
end
