return {
  name = 't',
  links = { { name = 'body', mass = 1, shapes = { { cone = 0.1 } } } },
}
