actions = { lift = { joint = 'elbow' } } --!
function step(dt) end
