function step(dt)
  module.id = 99; module.joint = nil; error('after writes') --!
end
