function step(dt)
  log(string.rep('L', 2e6))
end
