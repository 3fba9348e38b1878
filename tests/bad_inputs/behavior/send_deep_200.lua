local d = module.dock('front')
function step(dt)
  local t = {}; for i = 1, 200 do t = {t} end; d:send(t) --!
end
