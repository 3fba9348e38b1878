function step(dt)
  sim.random(0/0) --!
end
