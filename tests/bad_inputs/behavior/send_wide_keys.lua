local d = module.dock('front')
function step(dt)
  local t = {}; for i = 1, 1e4 do t['k' .. i] = true end; d:send(t) --!
end
