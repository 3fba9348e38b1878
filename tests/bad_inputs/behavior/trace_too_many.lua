function step(dt)
  for i = 1, 300 do module.trace("s" .. i, i) end
end
