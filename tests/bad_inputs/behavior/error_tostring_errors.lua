function step(dt) error(setmetatable({}, {__tostring = function() error('tostring too') end})) end --!
