function step(dt)
  coroutine.wrap(function() while true do end end)() --!
end
