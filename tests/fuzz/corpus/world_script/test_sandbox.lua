-- Behaviour VMs are sandboxed: no io, os, dofile, loadfile or binary chunks; `require` finds
-- only the project's Lua folders.
world.set{duration = 0.2}
local m = world.spawn("superbot", {behavior = "../behaviors/sandbox_probe.lua"})
world.at(0.1, function()
  expect(m:error() == nil, "probe ran: " .. tostring(m:error()))
end)
