-- Receives {n = 1, sub = {1}} from payload/send_then_mutate and faults if the sender's later
-- changes show through (payloads are copies), then mutates what it got.
function step(dt)
  local m = module.receive()
  if m then
    if m.data.n ~= 1 or m.data.sub[1] ~= 1 then error("payload aliased the sender's table") end
    m.data.sub[1] = 99
  end
end
