function step(dt)
  for i = 1, 1000 do setmetatable({}, {__gc = function() error('gc during step') end}) end
  collectgarbage()
end
