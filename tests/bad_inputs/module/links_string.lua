return {
  name = 't',
  links = 'many',
}
