local cs = {}
function step(dt)
  for i = 1, 1e6 do cs[#cs + 1] = coroutine.create(print) end --!
end
