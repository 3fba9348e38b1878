function step(dt)
  module.sensor('joint:pitch', 'sideways') --!
end
