-- Channel model: at rate 1, three messages sent in one step leave one per step, in order.
world.set{gravity = {0, 0, 0}, duration = 1}
world.channel{rate = 1}
local tx = world.spawn("superbot", {behavior = "../behaviors/chatter.lua", params = {role = "send", count = 1, burst = 3}})
local rx = world.spawn("superbot", {behavior = "../behaviors/chatter.lua", params = {role = "recv", rate = 1}})
world.connect(tx, "back", rx, "front")
world.at(0.5, function()
  expect(rx:error() == nil, tostring(rx:error()))
  local st = world.messages()
  expect(st.sent == 3 and st.received == 3 and st.dropped == 0, string.format("sent %d read %d dropped %d", st.sent, st.received, st.dropped))
end)
