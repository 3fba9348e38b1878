world.set{duration = 0.2}
world.spawn("/tmp/rm3d_bi_evil/evil.lua", {at = {0, 0, 0.1}}) --!
