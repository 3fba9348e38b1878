function step(dt)
  local j = module.joint('pitch'); j.angle(module.dock('front')) --!
end
