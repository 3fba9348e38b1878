function step(dt)
  log(setmetatable({}, {__tostring = function() error('no string') end})) --!
end
