-- For tests/worlds/noise_models.lua: an action driving a joint the module type lacks is a load
-- error naming this file, the declaring line and the joint.
actions = {
  left = {joint = "wheel_fl", mode = "velocity"},
  middle = {joint = "wheel_ml", mode = "velocity", noise = noise.gaussian(0.1)},  -- line 5: no such joint
}
function step(dt) end
