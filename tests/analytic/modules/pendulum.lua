-- A rigid pendulum for tests/analytic/pendulum_period.lua: a base block (the root, held in place
-- with spawn{fixed = true}) and a slender box arm hanging from a hinge about y through the module
-- origin. The world script reads this table (require "modules.pendulum") to compute the expected
-- period from the same masses, sizes and pivot, so the two cannot drift apart.
return {
  name = "pendulum",
  root = "base",
  links = {
    { name = "base", mass = 1.0, shapes = { { box = { 0.05, 0.05, 0.05 }, at = { 0, 0, 0.035 } } } },
    { name = "arm", mass = 0.5, shapes = { { box = { 0.02, 0.02, 0.40 }, at = { 0, 0, -0.20 } } } },
  },
  joints = {
    { name = "swing", parent = "base", child = "arm", pivot = { 0, 0, 0 }, axis = { 0, 1, 0 },
      continuous = true, torque = 1, speed = 3 },
  },
}
