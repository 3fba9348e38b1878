function step(dt)
  module.trace("x", nil)
end
