return {
  name = 't',
  links = { { name = 'body', mass = 'heavy', shapes = { { box = {0.1, 0.1, 0.1} } } } },
}
