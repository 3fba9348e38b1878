local d = module.dock('front')
function step(dt)
  d:send(string.rep('x', 1e6)) --!
end
