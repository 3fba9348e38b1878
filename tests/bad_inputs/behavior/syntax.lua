function step(dt)
  if then --!
end
