-- Dock-routed messages, one step per hop: a 20-module chain relays four messages from the
-- head; module k reads each at exactly (sent step + k), in FIFO order, each read consuming it.
world.set{gravity = {0, 0, 0}, duration = 0.8}
local chain = {}
for i = 1, 20 do
  chain[i] = world.spawn("superbot", {behavior = "../behaviors/relay.lua", params = {index = i - 1}})
  if i > 1 then world.connect(chain[i - 1], "back", chain[i], "front") end
end
world.at(0.7, function()
  for i, m in ipairs(chain) do expect(m:error() == nil, "module " .. i .. ": " .. tostring(m:error())) end
  for i = 2, 20 do
    expect(not chain[i]:dock_state("up").enabled, "module " .. i .. " read all four messages")
  end
end)
