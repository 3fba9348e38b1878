world.set{duration = 0.2}
world.spawn("superbot", {at = {0, 0, 0.043}, behavior = "../../../../../../../../../../tmp/rm3d_bi_evil/evil.lua"}) --!
