-- Sends what cannot be sent (for messages_dropped.lua): params.what = "function" or "big".
function step(dt)
  assert(module.dock("left"):send(1) == false, "nothing is engaged on left")
  local back = module.dock("back")
  if params.what == "function" then
    back:send({f = print})
  else
    back:send(string.rep("x", 2000))
  end
end
