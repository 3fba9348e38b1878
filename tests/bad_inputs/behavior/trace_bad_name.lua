function step(dt)
  module.trace("x y", 1)
end
