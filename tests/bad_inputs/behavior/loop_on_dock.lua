function step(dt) if sim.time() > 0.05 then module.dock('front'):disable() end end
function on_dock(d, e)
  while true do end --!
end
