-- Spreads a loop over many coroutines, each under the budget alone (lua_limits.lua): the budget
-- is per VM, so together they exceed it.
function step(dt)
  for k = 1, 100 do
    local co = coroutine.create(function() for i = 1, 1e6 do end end)
    coroutine.resume(co)
  end
end
