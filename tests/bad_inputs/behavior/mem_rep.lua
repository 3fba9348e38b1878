function step(dt)
  local s = string.rep('x', 1e9) --!
end
