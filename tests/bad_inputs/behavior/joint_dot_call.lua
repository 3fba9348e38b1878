function step(dt)
  module.joint('pitch').set_target(0.5) --!
end
