return {
  name = 't',
  links = { { name = 'body', mass = 0, shapes = { { box = {0.1, 0.1, 0.1} } } } },
}
