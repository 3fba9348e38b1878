-- A behaviour with a syntax error (for behaviour_faults.lua).
function step(dt)
  local x = 1
  x = = 2
end
