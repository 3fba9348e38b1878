function step(dt)
  error('strict failure') --!
end
