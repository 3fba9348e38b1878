-- Messages in flight over a connection that goes are dropped and counted; sending on a free
-- dock returns false; bad payloads (a function, over the size limit) fault only the sender
-- with file:line.
world.set{gravity = {0, 0, 0}, duration = 1}
world.channel{delay = 10, max_bytes = 1000}
local tx = world.spawn("superbot", {behavior = "../behaviors/chatter.lua", params = {role = "send", count = 5}})
local rx = world.spawn("superbot", {behavior = "../behaviors/chatter.lua", params = {role = "recv"}})
world.connect(tx, "back", rx, "front")
local fn = world.spawn("superbot", {at = {2, 0, 0}, behavior = "../behaviors/bad_sender.lua", params = {what = "function"}})
local big = world.spawn("superbot", {at = {3, 0, 0}, behavior = "../behaviors/bad_sender.lua", params = {what = "big"}})
local peer1 = world.spawn("superbot", {at = {2, 1, 0}})
local peer2 = world.spawn("superbot", {at = {3, 1, 0}})
world.connect(fn, "back", peer1, "front")
world.connect(big, "back", peer2, "front")
-- Disabled after step 3: step 4 still sends (behaviours run before the undock phase), then the
-- connection goes with all four messages in flight; step 5's send returns false.
world.at(0.05, function() tx:set_dock("back", false) end)
world.at(0.5, function()
  local st = world.messages()
  expect(st.sent == 4 and st.received == 0 and st.dropped == 4,
         string.format("sent %d read %d dropped %d: the four in flight when the connection went", st.sent, st.received, st.dropped))
  expect(tostring(fn:error()):find("bad_sender.lua:6: dock:send: a function at key 'f' cannot be copied", 1, true),
         "function payload: " .. tostring(fn:error()))
  expect(tostring(big:error()):find("bad_sender.lua:8: dock:send: value too large (over 1000 bytes)", 1, true),
         "big payload: " .. tostring(big:error()))
  expect(rx:error() == nil and tx:error() == nil, "the others run on")
  local ok, err = pcall(function() fn:set_dock("left", true) end)
  expect(not ok and err:find("is faulted", 1, true), "a faulted module's docks cannot be changed: " .. tostring(err))
end)
