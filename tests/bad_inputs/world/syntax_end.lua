world.set{duration = 0.2}
if true then
  print(1)
else else --!
end
