function step(dt)
  for i = 1, 257 do module.publish("k" .. i, i) end
end
