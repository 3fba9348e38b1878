function step(dt)
  local n = 0
  for i = 1, 1000 do coroutine.wrap(function() for k = 1, 1e6 do n = n + 1 end end)() end --!
end
