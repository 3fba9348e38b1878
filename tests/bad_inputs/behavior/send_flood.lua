local d = module.dock('front')
function step(dt)
  for i = 1, 1e5 do d:send(i) end --!
end
