return {
  name = 't',
  links = {{ name = 'body', mass = 1, shapes = { { box = {0.1, 0.1, 0.1} } } }},
  sensors = { { type = 'range', name = 'f', dir = {1, 0, 0}, min = 2, max = 0.1 } },
}
