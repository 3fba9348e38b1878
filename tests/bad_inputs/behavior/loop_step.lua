function step(dt)
  while true do end --!
end
