world.set{duration = 0.2}
world.spawn('superbot', {at = {0, 0, 0.1}, params = (function() local p = {} for i = 1, 1e6 do p = {p} end return p end)()}) --!
