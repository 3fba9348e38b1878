collectgarbage('stop')
function step(dt)
  for i = 1, 1e6 do local s = string.rep('z', 1000) .. i end --!
end
