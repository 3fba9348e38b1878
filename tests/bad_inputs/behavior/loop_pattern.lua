local s = string.rep('a', 50000)
function step(dt)
  s:find('.-.-.-.-.-.-.-b') --!
end
