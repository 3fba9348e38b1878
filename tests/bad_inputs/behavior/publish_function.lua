function step(dt)
  module.publish("f", {g = function() end})
end
