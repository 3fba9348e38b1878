-- A module under a Python policy (tests/python): observe() returns its pitch angle, the value
-- last heard on its front dock, and its step count; act(a) sets the pitch target from a[1] and,
-- when a[2] ~= 0, sends a[2] through its back dock (heard by the next module one step later).
act_size = 2
local pitch = module.joint("pitch")
local back = module.dock("back")
local heard, steps = 0, 0
function observe()
  return {pitch:angle(), heard, steps}
end
function act(a)
  pitch:set_target(a[1])
  if a[2] ~= 0 then back:send(a[2]) end
end
function step(dt)
  steps = steps + 1
  local msg = module.receive("front")
  while msg do
    heard = msg.data
    if params.hops ~= 0 then back:send(msg.data) end  -- relay further down the chain
    msg = module.receive("front")
  end
end
