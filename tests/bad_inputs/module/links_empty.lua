return {
  name = 't',
  links = {},
}
