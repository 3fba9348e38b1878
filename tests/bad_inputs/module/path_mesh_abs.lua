return {
  name = 't',
  links = { { name = 'body', mass = 1, shapes = { { mesh = '/etc/hostname' } } } },
}
