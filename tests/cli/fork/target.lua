-- Holds the pitch joint at a fixed target (the fork test edits this number).
local target = math.rad(30)

function step(dt)
  module.joint("pitch"):set_target(target)
end
