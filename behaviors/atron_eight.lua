-- The ATRON 8-shape's gait (worlds/atron_eight.lua): the module shared by the two rings turns
-- its equator, and with it one ring about the 8's long axis, at `spin` rad/s (the motor's
-- limit is 1 rad/s) after `delay` s; every other module holds its equator at 0.
-- params: spin (rad/s; nil: hold at 0), delay (s, default 1)
local equator = module.joint("equator")
local delay = params.delay or 1

function step(dt)
  if params.spin and sim.time() >= delay then
    equator:set_velocity(params.spin)
  else
    equator:set_target(0)
  end
end
