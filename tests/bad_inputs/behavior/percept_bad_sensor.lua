percepts = { tilt = { sensor = 'sonar' } } --!
function step(dt) end
