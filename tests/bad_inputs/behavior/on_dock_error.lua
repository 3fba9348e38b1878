function step(dt) if sim.time() > 0.05 then module.dock('front'):disable() end end
function on_dock(d, e)
  error('on_dock failed: ' .. tostring(d) .. ' ' .. tostring(e)) --!
end
