return {
  name = 't',
  links = { { name = 'a', mass = 1, shapes = { { box = {0.1, 0.1, 0.1} } } }, { name = 'b', mass = 1, shapes = { { box = {0.1, 0.1, 0.1}, at = {0.2, 0, 0} } } } },
  joints = {{ name = 'zzb', parent = 'zz', child = 'b', pivot = {0.1, 0, 0}, axis = {0, 0, 1}, lower = -1, upper = 1, torque = 1, speed = 1 }},
}
