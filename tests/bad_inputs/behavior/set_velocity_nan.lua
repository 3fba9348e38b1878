function step(dt)
  module.joint('pitch'):set_velocity(0/0) --!
end
