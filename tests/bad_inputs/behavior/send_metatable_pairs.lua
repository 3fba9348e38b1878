local d = module.dock('front')
function step(dt)
  d:send(setmetatable({1, 2}, {__pairs = function() error('pairs hook ran') end, __index = function() error('index hook ran') end})) --!
end
