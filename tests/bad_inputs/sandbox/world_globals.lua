-- Two modules run the same globals probe; the world sets a global of its own. Nothing may be
-- shared between VMs.
world.set{duration = 0.1}
rm3d_bi_world_leak = "world global visible in a behaviour"
getmetatable("").__index.rm3d_bi_mark = true
world.spawn("superbot", {at = {0, 0, 0.043}, behavior = "globals.lua"})
world.spawn("superbot", {at = {0, 1, 0.043}, behavior = "globals.lua"})
