local d = module.dock('front')
function step(dt)
  d:send(setmetatable({1}, {__gc = function() error('gc copied') end})) --!
end
