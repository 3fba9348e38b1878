world.set{duration = 0.2}
do
  local x <close> = setmetatable({}, {__close = function() error('close failed') end}) --!
end
