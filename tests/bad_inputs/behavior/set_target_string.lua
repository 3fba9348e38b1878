function step(dt)
  module.joint('pitch'):set_target('up') --!
end
