-- Faults only after t = 0.4, proving it was still stepping while its neighbours had faulted.
function step(dt)
  if sim.time() > 0.4 then error("still stepping at " .. sim.time()) end
end
