function step(dt)
  while true do pcall(error, 'x') end --!
end
