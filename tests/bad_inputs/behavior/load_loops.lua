function step(dt)
  load('while true do end')() --!
end
