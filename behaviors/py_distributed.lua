-- A module of a distributed policy run from Python (worlds/python/distributed.py): modules
-- coordinate only through dock messages. Python writes each module's action row and reads its
-- observation row; this behaviour carries them between the docks and the joint.
--   act(a):    a = {start, phase, lag, target}. First it reads what arrived on the front dock
--              (sent by the neighbour in the step before). start ~= 0 (the head): the module's
--              phase is a[2] and {phase, 1} goes out on the back dock. Otherwise, when a message
--              {phase, hops} arrived: the module's phase is that phase + lag, and {its phase,
--              hops + 1} goes out on the back dock, in the same step, so a message moves one hop
--              per step. The pitch servo takes `target` (rad).
--   observe(): {heard, phase, hops, head, pitch}: heard is 1 once a message has arrived, phase
--              the module's own phase (rad), hops how many hops the newest message came, head 1
--              when nothing is docked at the front, pitch the joint's angle (rad).
local pitch = module.joint("pitch")
local front, back = module.dock("front"), module.dock("back")

act_size = 4

function act(a)
  local got
  while true do
    local msg = module.receive("front")
    if not msg then break end
    if type(msg.data) == "table" and type(msg.data[1]) == "number" then got = msg.data end
  end
  if a[1] ~= 0 then
    state.phase, state.hops = a[2], 0
    back:send({ state.phase, 1 })
  elseif got then
    state.heard, state.phase, state.hops = 1, got[1] + a[3], got[2]
    back:send({ state.phase, state.hops + 1 })
  end
  pitch:set_target(a[4])
end

function observe()
  return { state.heard or 0, state.phase or 0, state.hops or 0,
           front:engaged() and 0 or 1, pitch:angle() }
end
