function step(dt)
  local d = module.dock('front'); d.enable(module.joint('pitch')) --!
end
