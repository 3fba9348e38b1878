local d = module.dock('front')
function step(dt)
  for i = 1, 10000 do d:send(string.rep('m', 60000)) end --!
end
