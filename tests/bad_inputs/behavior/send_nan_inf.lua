local d = module.dock('front')
function step(dt)
  d:send({0/0, 1/0, -1/0, math.mininteger, -0.0}) --!
end
