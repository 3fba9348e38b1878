function step(dt)
  while true do coroutine.resume(coroutine.create(function() end)) end --!
end
