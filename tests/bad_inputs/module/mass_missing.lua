return {
  name = 't',
  links = { { name = 'body', shapes = { { box = {0.1, 0.1, 0.1} } } } },
}
