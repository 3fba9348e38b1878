function step(dt) module.joint('pitch'):set_target(1e300) end
