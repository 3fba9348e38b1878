-- For tests/worlds/noise_models.lua: a dropout probability outside [0, 1] is a load error naming
-- this file and line.
percepts = {
  ahead = {sensor = "range:front", noise = {noise.gaussian(0.01), noise.dropout(1.5)}},  -- line 4
}
function step(dt) end
