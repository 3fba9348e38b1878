world.set{duration = 0.2}
for i = 1, 1e6 do world.spawn('superbot_box', {at = {i, 0, 0.1}}) end --!
