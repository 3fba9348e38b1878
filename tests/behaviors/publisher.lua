-- Publishes for tests/worlds/publish.lua: at step n, "step" = n and "info" = a table; "gone" is
-- published once at step 1 and removed (published nil) at step 3.
local n = 0
function step(dt)
  n = n + 1
  module.publish("step", n)
  module.publish("info", {name = module.name, list = {n, n * 2}, flag = n % 2 == 0})
  if n == 1 then module.publish("gone", "here") end
  if n == 3 then module.publish("gone", nil) end
end
