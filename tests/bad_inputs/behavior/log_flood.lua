function step(dt)
  for i = 1, 5000 do log('flood', i) end
end
