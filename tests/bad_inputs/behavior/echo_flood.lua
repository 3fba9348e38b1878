local d = module.dock('front')
function step(dt)
  while true do
    local m = module.receive()
    if not m then break end
    for i = 1, 10 do d:send(m.data) end
  end
end
