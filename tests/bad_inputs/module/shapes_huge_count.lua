local shapes = {}
for i = 1, 2e5 do shapes[i] = { sphere = 0.01, at = {i * 0.001, 0, 0} } end
return { name = 'huge', links = { { name = 'body', mass = 1, shapes = shapes } } }
