function step(dt)
  local t = {} for i = 1, 200 do t[i] = i end
  table.sort(t, function() while true do end end) --!
end
