-- For tests/worlds/noise_models.lua: a negative sigma is a load error naming this file and line.
percepts = {
  ahead = {sensor = "range:front",
           noise = noise.gaussian(-1)},  -- line 4: the error names this line
}
function step(dt) end
