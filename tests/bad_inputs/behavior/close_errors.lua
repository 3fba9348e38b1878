function step(dt)
  local x <close> = setmetatable({}, {__close = function() error('close failed') end}) --!
end
