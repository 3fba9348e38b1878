-- For tests/worlds/noise_models.lua: a percept naming a sensor the module type lacks (a typo) is
-- a load error naming this file, the declaring line and the sensor.
percepts = {
  ahead = {sensor = "range:front"},
  tilt = {sensor = "accelerometr", noise = noise.gaussian(0.05)},  -- line 5: misspelt
}
function step(dt) end
