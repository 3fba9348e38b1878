-- For tests/worlds/noise_models.lua: a sigma that is not a number is a load error; like the other
-- parameter checks it should name this file and line (noise.lua says "an error names the calling line").
percepts = {
  ahead = {sensor = "range:front", noise = noise.gaussian("0.01")},  -- line 4
}
function step(dt) end
