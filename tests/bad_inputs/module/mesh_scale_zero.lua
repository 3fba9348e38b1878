return {
  name = 't',
  links = { { name = 'body', mass = 1, shapes = { { mesh = '../../../assets/meshes/superbot_end_plate.obj', scale = 0 } } } },
}
