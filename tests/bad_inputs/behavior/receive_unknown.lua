function step(dt)
  module.receive('nose') --!
end
