percepts = { tilt = { sensor = 'accelerometer', map = function() error('map failed') end } } --!
function step(dt) module.sense('tilt') end
