-- worlds/nodders.lua: two SuperBots docked side by side, nodding (the tutorial's world,
-- docs/getting-started.md).
world.set{dt = 1 / 60, duration = 5, seed = 3}
world.ground{friction = 0.8}
local a = world.spawn("superbot", {behavior = "behaviors/nod.lua"})
local b = world.spawn("superbot", {behavior = "behaviors/nod.lua", params = {amplitude = 1.0}})
world.connect(a, "left", b, "right")   -- places b so the docks mate face to face, and locks them
world.place_on_ground(a)               -- a and what is docked to it, down onto the ground
world.on_end(function(t)               -- runs however the run ends (duration, --seconds, Ctrl-C)
  expect(a:error() == nil, "a did not fault")
  print(string.format("a is at x=%.3f y=%.3f after %.1f s", a:position().x, a:position().y, t))
end)
