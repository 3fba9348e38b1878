-- Host for behaviour cases: the behaviour under test (--param b=PATH, relative to this folder)
-- runs on one SuperBot ("probe"); a second one ("healthy") must stay unaffected.
world.set{duration = 0.25}
world.ground{}
world.spawn("superbot", {at = {0, 0, 0.043}, name = "probe", behavior = args.b,
                         params = {esc = "/tmp/rm3d_bi_escape"}})
world.spawn("superbot", {at = {0, 1, 0.043}, name = "healthy", behavior = "behaviors/hold.lua"})
