return {
  name = 't',
  links = { { name = 'body', mass = 1, shapes = { { sphere = 0 } } } },
}
