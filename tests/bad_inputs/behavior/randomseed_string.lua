function step(dt)
  math.randomseed('x') --!
end
