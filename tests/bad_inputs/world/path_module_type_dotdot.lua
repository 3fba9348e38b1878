world.set{duration = 0.2}
world.module_type("../../../../../../../../../../tmp/rm3d_bi_evil/evil.lua") --!
