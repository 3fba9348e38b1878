-- worlds/nodders.lua: two SuperBots docked side by side, nodding (the README tutorial's world).
world.set{dt = 1 / 60, duration = 5, seed = 3}
world.ground{friction = 0.8}
local a = world.spawn("superbot", {at = {0, 0, 0.053}, behavior = "behaviors/nod.lua"})
local b = world.spawn("superbot", {behavior = "behaviors/nod.lua", params = {amplitude = 1.0}})
world.connect(a, "left", b, "right")      -- places b so the docks mate face to face, and locks them
world.at(5, function()
  expect(a:error() == nil, "a did not fault")
  print("a is at", a:position().x, a:position().y)
end)
