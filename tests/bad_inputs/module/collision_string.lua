return {
  name = 't',
  links = { { name = 'body', mass = 1, shapes = { { box = {0.1, 0.1, 0.1} } }, collision = 'box' } },
}
