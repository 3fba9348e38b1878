-- Reads every message on every dock and logs how many arrived and the first one's type
-- (payload cases).
function step(dt)
  local n, first = 0, nil
  while true do
    local m = module.receive()
    if not m then break end
    n = n + 1
    first = first or type(m.data)
  end
  if n > 0 then log("received", n, first) end
end
