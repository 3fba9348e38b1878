-- Joint targets amp * (a uniform draw from the module's seeded stream), fixed at init.
local targets = {}
function init()
  for _, name in ipairs(module.joints()) do targets[name] = params.amp * (2 * sim.random() - 1) end
end
function step(dt)
  for _, name in ipairs(module.joints()) do module.joint(name):set_target(targets[name]) end
end
