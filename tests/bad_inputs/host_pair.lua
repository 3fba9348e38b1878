-- Host for payload cases: "probe" (--param b=PATH) is docked front-to-back to "peer"
-- (--param r=PATH, default behavior/receiver.lua), which reads and checks what arrives; a third
-- module ("healthy") stands apart.
world.set{duration = 0.25}
world.ground{}
local a = world.spawn("superbot", {at = {0, 0, 0.043}, name = "probe", behavior = args.b,
                                   params = {esc = "/tmp/rm3d_bi_escape"}})
local b = world.spawn("superbot", {name = "peer", behavior = args.r or "behavior/receiver.lua",
                                   params = {esc = "/tmp/rm3d_bi_escape"}})
world.connect(a, "front", b, "back")
world.spawn("superbot", {at = {0, 1, 0.043}, name = "healthy", behavior = "behaviors/hold.lua"})
