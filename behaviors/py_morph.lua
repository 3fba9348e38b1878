-- The gait of worlds/python/py_morph.lua's evolved bodies: the pitch joint follows a sine of
-- 1.5 s whose phase is params.phase quarter turns (0..3, from the genome).
local pitch = module.joint("pitch")
local phase = (params.phase or 0) * math.pi / 2
local amplitude = params.amplitude or 0.6

function step(dt)
  pitch:set_target(amplitude * math.sin(2 * math.pi * sim.time() / 1.5 + phase))
end
