function step(dt)
  assert(load('x = = 1')) --!
end
