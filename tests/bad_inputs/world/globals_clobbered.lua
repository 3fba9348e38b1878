world.set{duration = 0.2}
world.on_step(function() end)
world = nil
expect = nil
args = nil
print = nil
tostring = nil
error = nil
pcall = nil
