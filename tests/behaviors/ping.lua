-- Sends its step number on `back` at step params.send_at; checks arrival on the peer one step
-- later and that reading consumes (for messages_one_hop.lua).
local n = 0
function step(dt)
  n = n + 1
  if params.send_at and n == params.send_at then
    assert(module.dock("back"):send({step = n, text = "hi"}) == true)
    assert(module.dock("left"):send(1) == false, "nothing is engaged on left")
  end
  local msg = module.receive()
  if msg then
    assert(n == 6, "arrived at step " .. n .. ", expected 6")
    assert(msg.dock == "front" and msg.data.step == 5 and msg.data.text == "hi")
    assert(module.receive() == nil, "reading consumes")
  elseif n == 6 and not params.send_at then
    error("message did not arrive at step 6")
  end
end
