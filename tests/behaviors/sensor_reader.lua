-- Reads raw sensors from a behaviour (for sensors_basic.lua): one-argument and "velocity" forms,
-- a missing sensor's error, and a dock reading; disables its `up` dock once all checks passed.
function step(dt)
  if sim.time() < 0.5 then return end
  local a = module.sensor("accelerometer")
  assert(type(a) == "table" and a.z and a[3] == a.z, "accelerometer reads {x,y,z}")
  assert(type(module.sensor("joint:pitch")) == "number", "joint angle")
  assert(type(module.sensor("joint:pitch", "velocity")) == "number", "joint speed")
  local d = module.sensor("dock:front")
  assert(d.enabled == true and d.engaged == false, "dock reading")
  local ok, err = pcall(module.sensor, "accelerometr")
  assert(not ok and err:find("no sensor named 'accelerometr' on a superbot", 1, true), tostring(err))
  assert(module.has_sensor("gyro") and not module.has_sensor("sonar"), "has_sensor")
  module.dock("up"):disable()
end
