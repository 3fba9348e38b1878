return {
  name = 't',
  links = { { name = 'body', mass = 1 } },
}
