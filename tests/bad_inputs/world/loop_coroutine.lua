world.set{duration = 0.2}
coroutine.wrap(function() while true do end end)() --!
