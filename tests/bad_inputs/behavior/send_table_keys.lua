local d = module.dock('front')
function step(dt)
  d:send({[{}] = 1}) --!
end
