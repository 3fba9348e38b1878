local d = module.dock('front')
local t = {n = 1, sub = {1}}
local sent = false
function step(dt)
  if not sent then sent = d:send(t) end
  t.n = t.n + 1
  t.sub[1] = 7
end
