world.set{duration = 0.2}
local p = {}
for i = 1, 1e5 do p = {p} end
world.spawn('superbot', {params = p}) --!
