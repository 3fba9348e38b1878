-- Drives an ATRON's equator as a wheel: set_velocity(speed) every step, after an optional delay.
-- params: speed (rad/s, signed: the world works out which way is forward; the motor's limit is
-- 1 rad/s), delay (s, default 0: the wheel holds still until then).
local equator = module.joint("equator")
local speed = params.speed or 1
local delay = params.delay or 0

function step(dt)
  if sim.time() >= delay then
    equator:set_velocity(speed)
  else
    equator:set_target(0)
  end
end
