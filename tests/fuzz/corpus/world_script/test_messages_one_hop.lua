-- A message sent on a dock at step t is read by the docked module at step t+1, once.
world.set{duration = 0.5, gravity = {0, 0, 0}}
local a = world.spawn("superbot", {behavior = "../behaviors/ping.lua", params = {send_at = 5}})
local b = world.spawn("superbot", {behavior = "../behaviors/ping.lua"})
world.connect(a, "back", b, "front")
world.at(0.4, function()
  expect(b:error() == nil and a:error() == nil, "no faults: " .. tostring(a:error()) .. " " .. tostring(b:error()))
end)
