return {
  name = 't',
  links = { { name = 'a', mass = 1, shapes = { { sphere = 0.1 } } }, { name = 'a', mass = 1, shapes = { { sphere = 0.1 } } } },
}
