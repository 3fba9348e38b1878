-- A module whose pitch joint is driven from Python (worlds/python/py_chain.lua, rm3d.World with
-- policy=True): its observation row is {pitch angle (rad), pitch velocity (rad/s)}, its action
-- row one number, the pitch servo target (rad; the servo keeps it within the joint's limits).
local pitch = module.joint("pitch")

act_size = 1

function observe()
  return { pitch:angle(), pitch:velocity() }
end

function act(a)
  pitch:set_target(a[1])
end
