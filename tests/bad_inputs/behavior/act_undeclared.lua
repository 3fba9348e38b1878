function step(dt)
  module.act('lift', 1) --!
end
