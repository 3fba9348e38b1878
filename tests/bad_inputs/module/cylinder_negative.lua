return {
  name = 't',
  links = { { name = 'body', mass = 1, shapes = { { cylinder = {-1, 0.1} } } } },
}
