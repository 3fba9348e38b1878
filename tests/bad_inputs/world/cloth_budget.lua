-- 64 cloths of 256 x 256 nodes: each within its own limit, together past the world budget.
world.set{duration = 0.2}
for i = 1, 64 do
  world.cloth{corners = {{0, 0, i * 0.01}, {1, 0, i * 0.01}, {1, 1, i * 0.01}, {0, 1, i * 0.01}}, resolution = {256, 256}} --!
end
