-- Never returns from step (for runaway_scripts.lua).
function step(dt)
  while true do end
end
