local links = {}
for i = 1, 2e5 do links[i] = { name = 'l' .. i, mass = 1, shapes = { { sphere = 0.01 } } } end
return { name = 'huge', links = links }
