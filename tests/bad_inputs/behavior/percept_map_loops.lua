percepts = { tilt = { sensor = 'accelerometer', map = function() while true do end end } } --!
function step(dt) module.sense('tilt') end
