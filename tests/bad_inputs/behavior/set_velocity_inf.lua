function step(dt)
  module.joint('pitch'):set_velocity(-1/0) --!
end
