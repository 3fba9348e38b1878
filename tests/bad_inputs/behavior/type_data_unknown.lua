function step(dt)
  return module.type_data("no_such_type") --!
end
