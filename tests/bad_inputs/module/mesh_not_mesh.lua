return {
  name = 't',
  links = { { name = 'body', mass = 1, shapes = { { mesh = 'mesh_not_mesh.lua' } } } },
}
