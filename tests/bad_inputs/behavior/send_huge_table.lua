local d = module.dock('front')
function step(dt)
  local t = {}; for i = 1, 1e5 do t[i] = i end; d:send(t) --!
end
