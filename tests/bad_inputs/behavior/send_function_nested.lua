local d = module.dock('front')
function step(dt)
  d:send({a = {b = {c = function() end}}}) --!
end
