-- An endless loop and a memory hog each fault only their own module (instruction budget and
-- per-VM memory cap); the world goes on.
world.set{duration = 0.5}
local loop = world.spawn("superbot", {at = {0, 0, 1}, behavior = "../behaviors/endless_loop.lua"})
local hog = world.spawn("superbot", {at = {1, 0, 1}, behavior = "../behaviors/memory_hog.lua"})
local ok = world.spawn("superbot", {at = {2, 0, 1}, behavior = "behaviors/hold.lua"})
world.at(0.2, function()
  expect(tostring(loop:error()):find("instruction budget exceeded", 1, true), "loop: " .. tostring(loop:error()))
  expect(tostring(hog:error()):find("out of memory", 1, true), "hog: " .. tostring(hog:error()))
  expect(ok:error() == nil, "the third module is fine")
end)
