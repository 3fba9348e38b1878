function step(dt)
  coroutine.yield(1) --!
end
