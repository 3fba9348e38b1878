-- Relays messages down a chain: the head (nothing docked at its front) sends a counter on its
-- back dock every step; every other module forwards whatever arrives on its front dock to its
-- back dock in the same step, so a message reaches the module k hops away k steps later.
-- (Used by `rm3d bench relay_1000`.)
local front, back = module.dock("front"), module.dock("back")
local n = 0
function step(dt)
  n = n + 1
  if not front:engaged() then
    back:send(n)
    return
  end
  local msg = module.receive("front")
  while msg do
    back:send(msg.data)
    msg = module.receive("front")
  end
end
