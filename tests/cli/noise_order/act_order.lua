-- Acts on three noisy actions each step in the order params.order says ("forward", "reverse" or
-- "pairs"); noise streams are keyed by action name, so the order must not change the outcome.
actions = {
  pitch = {joint = "pitch", noise = noise.gaussian(0.05)},
  yaw = {joint = "yaw", noise = {noise.gaussian(0.05), noise.dropout(0.2)}},
  roll = {joint = "roll", noise = noise.uniform(0.1)},
}
percepts = {tilt = {sensor = "accelerometer", noise = noise.gaussian(0.1)},
            speed = {sensor = "gyro", noise = noise.drift(0.1)}}
local names = {"pitch", "roll", "yaw"}
if params.order == "reverse" then names = {"yaw", "roll", "pitch"} end
local sensed = {"tilt", "speed"}
if params.order == "reverse" then sensed = {"speed", "tilt"} end
local sum, told = {tilt = 0, speed = 0}, false
function step(dt)
  local t = sim.time()
  for _, n in ipairs(sensed) do
    local v = module.sense(n)
    if v then sum[n] = sum[n] + v[1] end
  end
  if params.order == "pairs" then
    for name in pairs(actions) do module.act(name, 0.3 * math.sin(t)) end
  else
    for _, name in ipairs(names) do module.act(name, 0.3 * math.sin(t)) end
  end
  if t >= 0.45 and not told then
    told = true
    log(string.format("percept sum %.17g %.17g", sum.tilt, sum.speed))
  end
end
