return {
  name = 't',
  links = { { name = 'body', mass = 1, shapes = { { box = {0/0, 0.1, 0.1} } } } },
}
