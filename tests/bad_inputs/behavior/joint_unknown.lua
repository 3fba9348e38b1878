function step(dt)
  module.joint('elbow') --!
end
