function step(dt)
  module.publish("big", string.rep("x", 70000))
end
