function step(dt)
  return table.unpack({}, 1, 1e8) --!
end
