function step(dt) step = 'not a function'; init = 5; on_dock = {} end
