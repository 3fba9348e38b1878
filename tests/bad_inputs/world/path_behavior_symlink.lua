world.set{duration = 0.2}
world.spawn("superbot", {at = {0, 0, 0.043}, behavior = "evil_link.lua"}) --!
