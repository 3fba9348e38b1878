function step(dt)
  module.receive(42) --!
end
