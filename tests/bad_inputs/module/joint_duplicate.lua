return {
  name = 't',
  links = { { name = 'a', mass = 1, shapes = { { sphere = 0.05 } } }, { name = 'b', mass = 1, shapes = { { sphere = 0.05, at = {0.2, 0, 0} } } }, { name = 'c', mass = 1, shapes = { { sphere = 0.05, at = {0.4, 0, 0} } } } },
  joints = { { name = 'j', parent = 'a', child = 'b', pivot = {0.1, 0, 0}, axis = {0, 0, 1}, lower = -1, upper = 1, torque = 1, speed = 1 }, { name = 'j', parent = 'b', child = 'c', pivot = {0.3, 0, 0}, axis = {0, 0, 1}, lower = -1, upper = 1, torque = 1, speed = 1 } },
}
