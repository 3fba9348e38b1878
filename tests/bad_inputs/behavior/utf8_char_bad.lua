function step(dt)
  return utf8.char(-1) --!
end
