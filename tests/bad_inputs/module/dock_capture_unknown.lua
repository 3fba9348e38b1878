return {
  name = 't',
  links = { { name = 'body', mass = 1, shapes = { { box = {0.1, 0.1, 0.1} } } } },
  docks = { { name = 'd', link = 'body', at = {0.05, 0, 0}, normal = {1, 0, 0}, capture = 'glue' } },
}
