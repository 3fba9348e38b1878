function step(dt)
  sim.gaussian(0, -1) --!
end
