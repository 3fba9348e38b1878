function step(dt)
  local t = nil
  return t.x --!
end
