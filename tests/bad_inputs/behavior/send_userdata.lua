local d = module.dock('front')
function step(dt)
  d:send(d) --!
end
