function step(dt)
  module.joint(5) --!
end
