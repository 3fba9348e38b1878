function step(dt)
  module.publish("a b", 1)
end
