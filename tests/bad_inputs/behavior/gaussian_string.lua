function step(dt)
  sim.gaussian('x') --!
end
