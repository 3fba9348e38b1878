local d = module.dock('front')
function step(dt)
  d:send(coroutine.create(print)) --!
end
