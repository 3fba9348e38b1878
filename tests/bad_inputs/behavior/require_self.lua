require('require_self') --!
function step(dt) end
