-- Message relay down a chain (for relay.lua). The head (index 0) sends numbered messages on
-- `back` at steps 10, 11, and twice at 12; every other module forwards each message it reads
-- on `front` to `back` in the same step. Module k must read message n at step (sent + k), in
-- order, and each read consumes it. Checks fail loudly (the module faults).
local n = 0
local expected = 1
local kSends = {[10] = {1}, [11] = {2}, [12] = {3, 4}}
local kSentAt = {10, 11, 12, 12}
local back = module.dock("back")
function step(dt)
  n = n + 1
  if params.index == 0 then
    for _, v in ipairs(kSends[n] or {}) do assert(back:send({seq = v}), "head could not send") end
    return
  end
  local msg = module.receive()
  while msg do
    assert(msg.dock == "front", "arrived on " .. msg.dock)
    assert(msg.data.seq == expected, "out of order: got " .. msg.data.seq .. ", expected " .. expected)
    local want = kSentAt[expected] + params.index
    assert(n == want, string.format("message %d read at step %d, expected %d", expected, n, want))
    if back:engaged() then back:send(msg.data) end
    expected = expected + 1
    msg = module.receive()
  end
  if expected == 5 then module.dock("up"):disable() end  -- all four arrived: show it to the world
end
