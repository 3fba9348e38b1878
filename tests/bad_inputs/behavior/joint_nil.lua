function step(dt)
  module.joint() --!
end
