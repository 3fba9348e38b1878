function step(dt)
  module.sensor('sonar') --!
end
