local n = noise.gaussian(-1) --!
function step(dt) end
