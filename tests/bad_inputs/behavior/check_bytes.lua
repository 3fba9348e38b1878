-- Receives the byte string from payload/send_bytes and faults if a byte changed.
local want = "a\0b\xff\xfe\xc3\x28" .. string.rep("\1", 10)
function step(dt)
  local m = module.receive()
  if m and m.data ~= want then error("payload changed in transit: " .. #tostring(m.data) .. " bytes") end
end
