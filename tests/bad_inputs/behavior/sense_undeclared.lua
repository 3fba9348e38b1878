function step(dt)
  module.sense('tilt') --!
end
