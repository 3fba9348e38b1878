-- Message channel probe (for the channel tests). As params.role == "send" it sends its step
-- number on `back` every step up to params.count (params.burst messages per step); as "recv"
-- it checks each message's delay against params.delay and FIFO order, and shows how many it
-- read by setting its pitch target to count / 1000 rad.
local n, got, last = 0, 0, -1
local pitch = module.joint("pitch")
function step(dt)
  n = n + 1
  if params.role == "send" then
    if n <= (params.count or 100) then
      for k = 1, params.burst or 1 do module.dock("back"):send({step = n, k = k}) end
    end
    return
  end
  local msg = module.receive()
  while msg do
    local seq = msg.data.step * 100 + msg.data.k
    assert(seq > last, "out of order")
    last = seq
    if params.delay then
      assert(n == msg.data.step + 1 + params.delay,
             string.format("sent at %d, read at %d, expected delay %d", msg.data.step, n, params.delay))
    end
    if params.rate then
      assert(n == msg.data.step + msg.data.k, "rate 1: message k of a step leaves k - 1 steps later")
    end
    got = got + 1
    msg = module.receive()
  end
  pitch:set_target(got / 1000)
  state.got = got
end
