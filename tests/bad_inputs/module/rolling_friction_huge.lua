return {
  name = 't',
  links = { { name = 'body', mass = 1, rolling_friction = 1, shapes = { { box = {0.1, 0.1, 0.1} } } } },
}
