-- Channel model: with loss 0.25 and 2 steps of extra delay, each message arrives exactly 3 steps
-- after it was sent, in order, and about a quarter are lost (seeded: the same every run).
world.set{gravity = {0, 0, 0}, duration = 5, seed = 11}
world.channel{loss = 0.25, delay = 2}
local tx = world.spawn("superbot", {behavior = "../behaviors/chatter.lua", params = {role = "send", count = 240}})
local rx = world.spawn("superbot", {behavior = "../behaviors/chatter.lua", params = {role = "recv", delay = 2}})
world.connect(tx, "back", rx, "front")
world.at(4.9, function()
  expect(rx:error() == nil, tostring(rx:error()))
  local st = world.messages()
  expect(st.sent == 240, "240 sent, got " .. st.sent)
  local lost = st.dropped / st.sent
  expect(lost > 0.18 and lost < 0.32, string.format("lost %.3f of the messages, expected about 0.25", lost))
  expect(st.received + st.dropped == 240, "every message was either read or lost")
end)
