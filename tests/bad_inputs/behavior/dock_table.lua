function step(dt)
  module.dock({}) --!
end
