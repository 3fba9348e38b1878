local d = module.dock('front')
function step(dt)
  d:send("a\0b\xff\xfe\xc3\x28" .. string.rep("\1", 10)) --!
end
