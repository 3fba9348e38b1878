getmetatable('').__index = function() error('strings broken') end
local d = module.dock('front')
function step(dt)
  d:send('abc') --!
end
