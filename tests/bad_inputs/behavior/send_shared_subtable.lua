local d = module.dock('front')
function step(dt)
  local s = {1}; d:send({s, s, s}) --!
end
