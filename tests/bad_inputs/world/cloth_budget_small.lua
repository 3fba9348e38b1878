-- 64 cloths of 64 x 64 nodes against a small --memory-budget.
world.set{duration = 0.2}
for i = 1, 64 do
  world.cloth{corners = {{0, 0, i * 0.01}, {1, 0, i * 0.01}, {1, 1, i * 0.01}, {0, 1, i * 0.01}}, resolution = {64, 64}} --!
end
