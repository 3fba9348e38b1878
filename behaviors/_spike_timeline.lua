-- params.timeline = {{t, "target", joint, rad} | {t, "disable", dock} | {t, "enable", dock}}
-- params.crawl = {from, to, index, lag, amplitude, period}
local gaits = require("gaits")
local done = {}
function step(dt)
  local t = sim.time()
  for i, e in ipairs(params.timeline or {}) do
    if not done[i] and t >= e[1] then
      done[i] = true
      if e[2] == "target" then module.joint(e[3]):set_target(e[4])
      elseif e[2] == "disable" then module.dock(e[3]):disable()
      elseif e[2] == "enable" then module.dock(e[3]):enable() end
    end
  end
  for _, c in ipairs(params.crawls or {}) do
    if t >= c.from and t < c.to then
      module.joint("pitch"):set_target(gaits.wave(t - c.from, c.index, c.amplitude or 0.4, c.period or 1.5, c.lag or (2 * math.pi / 5)))
    elseif t >= c.to and t < c.to + 0.05 then
      module.joint("pitch"):set_target(0)
    end
  end
  while module.receive() do end
end
