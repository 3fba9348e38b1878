return {
  name = 't',
  links = { { name = 'body', mass = 1, friction = -1, shapes = { { box = {0.1, 0.1, 0.1} } } } },
}
