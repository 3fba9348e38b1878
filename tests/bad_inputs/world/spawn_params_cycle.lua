world.set{duration = 0.2}
local p = {}
p.self = p
world.spawn('superbot', {params = p}) --!
