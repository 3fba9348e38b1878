getmetatable('').__index = function() error('strings broken') end
function step(dt)
  return ('a'):rep(2) --!
end
