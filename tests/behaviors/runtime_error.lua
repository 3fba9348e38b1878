-- A behaviour that fails at run time after one second (for behaviour_faults.lua).
local j = module.joint("pitch")
function step(dt)
  j:set_target(0.3)
  if sim.time() > 1 then
    local missing = nil
    return missing.field
  end
end
