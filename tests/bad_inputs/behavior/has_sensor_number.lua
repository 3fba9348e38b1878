function step(dt)
  module.has_sensor({}) --!
end
