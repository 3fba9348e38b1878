local d = module.dock('front')
function step(dt)
  d.send(module.joint('pitch'), 1) --!
end
