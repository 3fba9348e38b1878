world.set{duration = 0.2}
world.mesh{file = "ok.lua"} --!
