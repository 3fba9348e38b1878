local d = module.dock('front')
function step(dt)
  d:send(print) --!
end
