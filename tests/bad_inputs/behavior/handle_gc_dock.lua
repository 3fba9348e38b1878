function step()
  getmetatable(module.dock("front")).__index = nil --!
end
