-- Reports on_dock events through its pitch joint, so a world can see them: "engaged" turns
-- pitch to +0.5 rad, "disengaged" to -0.5, "broken" to -1.0; "captured" and "stalled" (a
-- capture joint drawing the docks in) leave it (for the docking tests).
local pitch = module.joint("pitch")
local target = 0
function on_dock(dock, event)
  assert(type(dock) == "userdata" and dock:name(), "on_dock gets a Dock")
  if event == "engaged" then target = 0.5
  elseif event == "disengaged" then target = -0.5
  elseif event == "broken" then target = -1.0
  elseif event == "captured" or event == "stalled" then return
  else error("unexpected dock event " .. tostring(event)) end
end
function step(dt) pitch:set_target(target) end
