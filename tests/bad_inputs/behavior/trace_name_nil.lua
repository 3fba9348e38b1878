function step(dt)
  module.trace(nil, 1)
end
