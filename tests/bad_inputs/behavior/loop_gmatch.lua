local s = string.rep('a', 30000)
function step(dt)
  for x in s:gmatch('a-a-a-a-a-a-b') do end --!
end
