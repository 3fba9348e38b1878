local d = module.dock('front')
function step(dt)
  for i = 1, 2000 do d:send(string.rep('m', 60000)) end --!
end
