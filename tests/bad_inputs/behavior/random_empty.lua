function step(dt)
  sim.random(5, 1) --!
end
