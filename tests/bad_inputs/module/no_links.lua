return {
  name = 't',
}
