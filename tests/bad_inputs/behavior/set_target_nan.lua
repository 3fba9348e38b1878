function step(dt)
  module.joint('pitch'):set_target(0/0) --!
end
