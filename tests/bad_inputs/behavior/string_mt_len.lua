getmetatable('').__len = function() error('len broken') end
getmetatable('').__concat = function() error('concat broken') end
function step(dt) end
