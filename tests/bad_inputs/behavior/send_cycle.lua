local d = module.dock('front')
function step(dt)
  local t = {}; t.t = t; d:send(t) --!
end
