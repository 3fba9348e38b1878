return {
  name = 't',
  links = { { name = 'body', mass = 1, color = {5, -1, 0}, shapes = { { box = {0.1, 0.1, 0.1} } } } },
}
