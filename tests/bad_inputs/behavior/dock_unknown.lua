function step(dt)
  module.dock('nose') --!
end
